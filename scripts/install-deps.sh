#!/usr/bin/env bash
# Installs the Debian packages quadcosim needs (Debian 12 / Ubuntu 24.04). Does nothing when all are
# present. Runs apt-get as root, or through sudo otherwise.
set -euo pipefail

packages=(
  build-essential cmake pkg-config libzstd-dev
  libeigen3-dev libyaml-cpp-dev libcli11-dev libfmt-dev nlohmann-json3-dev
  cyclonedds-dev cyclonedds-tools
  libxml2-dev libminizip-dev  # FMI: modelDescription.xml and .fmu archives (src/fmi)
  libwebsocketpp-dev libasio-dev  # --foxglove: the Foxglove WebSocket server (src/foxglove)
  libssl-dev openssl  # DDS Security keystores (libcrypto); openssl checks them in the tests
  libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-matplotlib python3-numpy
  pybind11-dev python3-dev python3-pytest  # the Python module (src/python) and its tests (tests/python)
  python3-torch libopenblas0-serial  # examples/learn_hover.py: PPO learns to hover (tests/python/test_learn_hover.py);
                                     # OpenBLAS makes torch's matrix products several times faster than the reference BLAS
  python3-venv python3-pip python3-setuptools python3-wheel  # `pip install .` into a venv (tests/install)
  colcon python3-colcon-ros python3-colcon-cmake python3-colcon-package-information  # package.xml as a ROS 2 workspace reads it; `colcon list` (tests/install)
  slurm-wlm munge  # a private single-node Slurm cluster for the sweep job array test (tests/sweep/slurm_test.sh)
  iproute2  # ip netns, veth, tc: the two-namespace and network fault tests (tests/faults)
  nftables  # nft: packet loss, bursts and cuts on the veth between the namespaces (tests/faults)
  chromium  # headless rendering check of report.html (tools/test_report.py)
  clang-format  # the C++ style, checked by the test style.clang_format (scripts/format.sh)
  clang libclang-rt-dev  # the compiler the build prefers (CMakeLists.txt), the sanitizer build and libFuzzer
                         # targets (scripts/sanitize.sh); clang-14 and libclang-rt-14-dev on Debian 12
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
