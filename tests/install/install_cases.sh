#!/usr/bin/env bash
# Installing quadcosim: install_cases.sh QUADCOSIM SOURCE_DIR CASE BUILD_DIR PYTHON
#   prefix      `cmake --install BUILD --prefix P` into a temporary prefix, then from P alone: a scenario
#               run with its plots (the tools from P/share/quadcosim), `fmu export` (the FMU library from
#               P/lib/quadcosim) and the Python module from P's site-packages.
#   pip         `pip install --no-build-isolation --no-index .` into a fresh venv (Debian's python3-venv
#               and python3-pip, no PyPI), then the module imported from the venv runs a scenario.
#   colcon      colcon (Debian's colcon with python3-colcon-ros) sees package.xml: a ROS 2 CMake package.
# Exits 77 (skipped) with the reason when the machine lacks what a case needs.
set -euo pipefail
quadcosim="$1" source_dir="$2" case_name="$3" build_dir="$4" python="${5:-/usr/bin/python3}"
work=$(mktemp -d /tmp/quadcosim-install-XXXXXX)
trap 'rm -rf "$work"' EXIT
cd "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
scenario_rel=paper/altitude_step.yaml

site_dir() {  # the module's folder under a prefix, as src/python/CMakeLists.txt installs it
  "$python" -c 'import sys; print("lib/python%d.%d/site-packages" % sys.version_info[:2])'
}

case "$case_name" in
  prefix)
    cmake --install "$build_dir" --prefix "$work/p" > install.log || { cat install.log; fail "cmake --install failed"; }
    p="$work/p"
    for f in bin/quadcosim lib/quadcosim/quadcosim_fmu.so share/quadcosim/tools/plot_run.py share/quadcosim/tools/report.py \
             "share/quadcosim/scenarios/$scenario_rel" share/quadcosim/package.xml share/doc/quadcosim/README.md \
             share/doc/quadcosim/python.md; do
      [ -e "$p/$f" ] || fail "$f was not installed"
    done
    # The installed CLI, with nothing pointing at the build or source tree.
    env -u QUADCOSIM_TOOLS_DIR -u QUADCOSIM_SCENARIOS_DIR -u QUADCOSIM_FMU_LIBRARY \
      "$p/bin/quadcosim" run "$p/share/quadcosim/scenarios/$scenario_rel" --out run > run.log 2>&1 ||
      { cat run.log; fail "the installed quadcosim could not run $scenario_rel"; }
    for f in trajectory.csv metrics.json step_z.png overview.png report.html; do
      [ -s "run/$f" ] || fail "run/$f missing after the installed run"
    done
    "$quadcosim" run "$source_dir/scenarios/$scenario_rel" --out ref --no-plots > /dev/null
    cmp run/trajectory.csv ref/trajectory.csv || fail "the installed CLI's trajectory differs from the build tree's"
    env -u QUADCOSIM_FMU_LIBRARY "$p/bin/quadcosim" fmu export plant --out plant.fmu > fmu.log 2>&1 ||
      { cat fmu.log; fail "fmu export from the prefix failed"; }
    grep -q "lib/quadcosim/quadcosim_fmu.so" fmu.log || { cat fmu.log; fail "fmu export did not take the installed library"; }
    # The installed module, when it was built.
    if compgen -G "$build_dir/python/quadcosim/_quadcosim*.so" > /dev/null; then
      site="$p/$(site_dir)"
      [ -f "$site/quadcosim/__init__.py" ] || fail "the Python module was not installed in $site"
      PYTHONPATH="$site" "$python" - "$p/share/quadcosim/scenarios/$scenario_rel" "$site" ref/trajectory.csv <<'PYEOF' ||
import sys, numpy, quadcosim
assert quadcosim.__file__.startswith(sys.argv[2]), quadcosim.__file__
r = quadcosim.run(sys.argv[1])
ref = numpy.genfromtxt(sys.argv[3], delimiter=",", names=True)
assert r.passed and numpy.array_equal(r.trajectory["z"], ref["z"]), "installed module: other numbers"
print("installed module:", quadcosim.__file__)
PYEOF
        fail "the installed Python module did not run the scenario"
    else
      echo "note: the Python module was not built; its installation was not checked"
    fi
    echo "prefix: installed and ran from $p"
    ;;
  pip)
    compgen -G "$build_dir/python/quadcosim/_quadcosim*.so" > /dev/null ||
      { echo "SKIP: the Python module was not built (needs pybind11-dev and python3-dev)"; exit 77; }
    "$python" -m venv --help > /dev/null 2>&1 || { echo "SKIP: $python has no venv module (Debian: python3-venv)"; exit 77; }
    "$python" -m venv --system-site-packages venv > venv.log 2>&1 ||
      { cat venv.log; echo "SKIP: $python -m venv cannot make a venv (Debian: python3-venv)"; exit 77; }
    venv/bin/python -m pip --version > /dev/null 2>&1 || { echo "SKIP: no pip for $python (Debian: python3-pip)"; exit 77; }
    # The source tree's build/ may not be the build under test: point setup.py at it.
    QUADCOSIM_BUILD_DIR="$build_dir" venv/bin/python -m pip install --no-build-isolation --no-index --no-deps \
      "$source_dir" > pip.log 2>&1 || { cat pip.log; fail "pip install of $source_dir failed"; }
    venv/bin/python - "$source_dir/scenarios/$scenario_rel" "$work/venv" <<'PYEOF' || fail "the pip-installed module did not run"
import sys, quadcosim
assert quadcosim.__file__.startswith(sys.argv[2]), "imported " + quadcosim.__file__ + ", not the venv's"
r = quadcosim.run(sys.argv[1])
assert r.passed, r.table
print("pip-installed module:", quadcosim.__file__, r)
PYEOF
    venv/bin/python -m pip show quadcosim > show.log 2>&1 || fail "pip show quadcosim failed: $(cat show.log)"
    grep -q "^Version: " show.log || fail "pip does not list quadcosim: $(cat show.log)"
    ;;
  colcon)
    command -v colcon > /dev/null || { echo "SKIP: colcon is not installed (Debian: colcon python3-colcon-ros)"; exit 77; }
    mkdir -p ws/src && ln -s "$source_dir" ws/src/quadcosim
    (cd ws && colcon list) > list.log 2>&1 || { cat list.log; fail "colcon list failed"; }
    grep -q "^quadcosim.*(ros.cmake)" list.log ||
      { cat list.log; if grep -q "(cmake)" list.log; then echo "SKIP: colcon has no ROS package support (python3-colcon-ros)"; exit 77; fi
        fail "colcon does not see quadcosim as a ROS 2 CMake package"; }
    cat list.log
    ;;
  *) fail "unknown case $case_name" ;;
esac
