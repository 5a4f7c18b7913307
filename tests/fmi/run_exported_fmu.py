"""Runs an exported quadcosim FMU the way an importer does, with nothing of quadcosim but the .fmu: unzip it,
read modelDescription.xml, dlopen binaries/<platform>/<modelIdentifier>.so with ctypes, instantiate it with
the GUID (token) and resources of the XML, and step it through the FMI 2.0 or 3.0 C API by the value
references the XML declares. Checks the results against closed forms computed from the XML's start values:
   plant: constant rotor speeds W from rest: every rotor reaches W (the default motors are ideal) and
          z(t) = a t^2 / 2, v_z(t) = a t with a = 4 kt W^2 / m - g, the specific force a + g;
   controller: its first command from the start values (on the ground, reference z from the XML), the
          paper's altitude law u1 = m g + kp (z_ref - z) split over four rotors: W = sqrt(u1 / (4 kt)).
Also: instantiation with another GUID is refused (a null instance), and a step that is not a whole number
of periods fails.
   usage: run_exported_fmu.py FMU plant|controller"""
import ctypes
import json
import math
import os
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile

fmu, kind = sys.argv[1], sys.argv[2]
work = tempfile.mkdtemp()
zipfile.ZipFile(fmu).extractall(work)
root = ET.parse(os.path.join(work, "modelDescription.xml")).getroot()
v3 = root.get("fmiVersion") == "3.0"
guid = root.get("instantiationToken" if v3 else "guid").encode()
ident = root.find("CoSimulation").get("modelIdentifier")
so = os.path.join(work, "binaries", "x86_64-linux" if v3 else "linux64", ident + ".so")
lib = ctypes.CDLL(so)

variables = {}  # name -> (vr, start)
if v3:
    for e in root.find("ModelVariables"):
        variables[e.get("name")] = (int(e.get("valueReference")), e.get("start"))
else:
    for sv in root.find("ModelVariables").findall("ScalarVariable"):
        variables[sv.get("name")] = (int(sv.get("valueReference")), sv[0].get("start"))
vr = lambda name: variables[name][0]
start = lambda name: float(variables[name][1])

messages = []
# FMI 2's logger is variadic (message is a printf format). On x86-64 the first variadic argument travels
# in the register of a sixth fixed one, so a fixed-argument callback reads the text of a "%s" message.
LOG2 = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p,
                        ctypes.c_char_p)
LOG3 = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p)
log2 = LOG2(lambda env, inst, status, cat, msg, arg: messages.append((arg if msg == b"%s" else msg).decode()))
log3 = LOG3(lambda env, status, cat, msg: messages.append(msg.decode()))
libc = ctypes.CDLL(None)
ALLOC = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_size_t, ctypes.c_size_t)
FREE = ctypes.CFUNCTYPE(None, ctypes.c_void_p)
libc.calloc.restype = ctypes.c_void_p
alloc = ALLOC(lambda n, size: libc.calloc(n, size))
free = FREE(lambda p: libc.free(ctypes.c_void_p(p)))


class Callbacks2(ctypes.Structure):
    _fields_ = [("logger", LOG2), ("allocateMemory", ALLOC), ("freeMemory", FREE),
                ("stepFinished", ctypes.c_void_p), ("componentEnvironment", ctypes.c_void_p)]


callbacks = Callbacks2(log2, alloc, free, None, None)
resources = os.path.join(work, "resources")


def instantiate(token):
    if v3:
        f = lib.fmi3InstantiateCoSimulation
        f.restype = ctypes.c_void_p
        f.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_bool, ctypes.c_bool,
                      ctypes.c_bool, ctypes.c_bool, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, LOG3,
                      ctypes.c_void_p]
        return f(b"i", token, (resources + "/").encode(), False, True, False, False, None, 0, None, log3, None)
    f = lib.fmi2Instantiate
    f.restype = ctypes.c_void_p
    f.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.POINTER(Callbacks2),
                  ctypes.c_int, ctypes.c_int]
    return f(b"i", 1, token, ("file://" + resources).encode(), ctypes.byref(callbacks), 0, 1)


def call(name, *args):
    status = getattr(lib, name)(*args)
    return status


assert instantiate(b"{00000000-0000-0000-0000-000000000000}") is None, "another GUID was accepted"
inst = ctypes.c_void_p(instantiate(guid))
assert inst.value, f"instantiation with the XML's GUID failed: {messages}"
D = ctypes.c_double
if v3:
    assert call("fmi3EnterInitializationMode", inst, False, D(0), D(0), False, D(0)) == 0, messages
    assert call("fmi3ExitInitializationMode", inst) == 0, messages
else:
    assert call("fmi2SetupExperiment", inst, 0, D(0), D(0), 0, D(0)) == 0, messages
    assert call("fmi2EnterInitializationMode", inst) == 0, messages
    assert call("fmi2ExitInitializationMode", inst) == 0, messages


def set_real(names, values):
    n = len(names)
    vrs = (ctypes.c_uint32 * n)(*[vr(x) for x in names])
    vals = (D * n)(*values)
    rc = call("fmi3SetFloat64", inst, vrs, ctypes.c_size_t(n), vals, ctypes.c_size_t(n)) if v3 else \
        call("fmi2SetReal", inst, vrs, ctypes.c_size_t(n), vals)
    assert rc == 0, (names, messages)


def get_real(names):
    n = len(names)
    vrs = (ctypes.c_uint32 * n)(*[vr(x) for x in names])
    vals = (D * n)()
    rc = call("fmi3GetFloat64", inst, vrs, ctypes.c_size_t(n), vals, ctypes.c_size_t(n)) if v3 else \
        call("fmi2GetReal", inst, vrs, ctypes.c_size_t(n), vals)
    assert rc == 0, (names, messages)
    return list(vals)


def do_step(t, h):
    if v3:
        flags = [ctypes.c_bool() for _ in range(3)]
        last = D()
        return call("fmi3DoStep", inst, D(t), D(h), True, *[ctypes.byref(f) for f in flags], ctypes.byref(last))
    return call("fmi2DoStep", inst, D(t), D(h), 1)


period = float(root.find("DefaultExperiment").get("stepSize"))
if kind == "plant":  # the vehicle as the XML's parameters declare it
    m, g, kt = start("vehicle.mass_kg"), start("vehicle.gravity_m_s2"), start("vehicle.kt_N_per_rad2_s2")
else:  # the controller's knowledge of the vehicle: its configuration in resources/
    vehicle = json.load(open(os.path.join(resources, "quadcosim.json")))["vehicle"]
    m, g, kt = vehicle["mass_kg"], vehicle["gravity_m_s2"], vehicle["kt_N_per_rad2_s2"]
omega_cmd = [f"omega_cmd[{i}]" for i in range(1, 5)]
if kind == "plant":
    W = 5000.0
    set_real(omega_cmd, [W] * 4)
    t = 0.0
    for _ in range(50):  # 0.5 s in steps of two periods
        assert do_step(t, 2 * period) == 0, messages
        t = round(t + 2 * period, 12)
    z, vz, fz = get_real(["p_W[3]", "v_W[3]", "f_B[3]"])
    omega = get_real([f"omega[{i}]" for i in range(1, 5)])
    a = 4 * kt * W * W / m - g
    assert omega == [W] * 4, omega
    assert math.isclose(z, a * t * t / 2, rel_tol=1e-9), (z, a * t * t / 2)
    assert math.isclose(vz, a * t, rel_tol=1e-9), (vz, a * t)
    assert math.isclose(fz, a + g, rel_tol=1e-12), (fz, a + g)
    print(f"plant: t = {t} s, z = {z!r} m (closed form {a * t * t / 2!r}), v_z = {vz!r} m/s, f_z = {fz!r} m/s2")
else:
    kp = start("controller.altitude.kp")
    assert do_step(0.0, period) == 0, messages
    cmd = get_real(omega_cmd)
    u1 = m * g + kp * (start("ref.p_W[3]") - start("p_W[3]"))
    W = math.sqrt(u1 / (4 * kt))
    assert all(math.isclose(c, W, rel_tol=1e-12) for c in cmd), (cmd, W)
    print(f"controller: omega_cmd = {cmd[0]!r} rad/s (closed form {W!r})")

# A step that is not a whole number of periods is refused with a message.
before = len(messages)
assert do_step(t if kind == "plant" else period, period * 0.5) != 0, "a half-period step was accepted"
assert len(messages) > before, "the refusal logged nothing"
print("refused half step:", messages[-1])
if v3:
    call("fmi3Terminate", inst)
    lib.fmi3FreeInstance(inst)
else:
    call("fmi2Terminate", inst)
    lib.fmi2FreeInstance(inst)
print("ok")
