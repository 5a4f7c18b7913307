"""Builds the Python module quadcosim with the project's CMake for `pip install .` (pyproject.toml).

The compiled core and the package's Python files are what `cmake --build BUILD --target
quadcosim_python` puts in BUILD/python/quadcosim; this copies them into the wheel. BUILD is
$QUADCOSIM_BUILD_DIR, else build/ beside this file: configured first (Release, for this Python) when
it has no CMakeCache.txt, and refused when it was configured for another Python (its module would not
import here): then point QUADCOSIM_BUILD_DIR at a build for this one.
"""
import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent


class BinaryDistribution(Distribution):
    """A wheel for this platform and Python (it holds a compiled module), not a pure one."""

    def has_ext_modules(self):
        return True


class CMakeBuild(build_py):
    def run(self):
        build = Path(os.environ.get("QUADCOSIM_BUILD_DIR") or ROOT / "build").resolve()
        if not (build / "CMakeCache.txt").exists():
            subprocess.check_call(["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                                   f"-DPython_EXECUTABLE={sys.executable}"])
        jobs = os.environ.get("QUADCOSIM_JOBS", "2")
        subprocess.check_call(["cmake", "--build", str(build), "--target", "quadcosim_python", "-j", jobs])
        package = build / "python" / "quadcosim"
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        cores = sorted(package.glob("_quadcosim*.so"))
        if not any(c.name == "_quadcosim" + suffix for c in cores):
            raise SystemExit(
                f"{build} holds the module for another Python ({', '.join(c.name for c in cores) or 'none'}; this "
                f"Python {sys.version.split()[0]} needs _quadcosim{suffix}, or pybind11-dev/python3-dev are missing "
                f"and CMake skipped the module). Set QUADCOSIM_BUILD_DIR to a build configured with "
                f"-DPython_EXECUTABLE={sys.executable}.")
        super().run()  # the package's Python files, from src/python/quadcosim
        target = Path(self.build_lib) / "quadcosim"
        for f in package.iterdir():
            if f.suffix in (".py", ".pyi") or f.name == "py.typed" or f.name == "_quadcosim" + suffix:
                shutil.copy2(f, target / f.name)


# setuptools' own working folders go under build/python-wheel, away from CMake's files in build/.
work = ROOT / "build" / "python-wheel"
work.mkdir(parents=True, exist_ok=True)
setup(
    distclass=BinaryDistribution,
    cmdclass={"build_py": CMakeBuild},
    packages=["quadcosim"],
    package_dir={"quadcosim": "src/python/quadcosim"},
    options={"build": {"build_base": str(work)}, "egg_info": {"egg_base": str(work)}},
)
