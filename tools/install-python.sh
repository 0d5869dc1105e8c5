#!/usr/bin/env bash
# Makes `import portalsim` work for Debian's /usr/bin/python3 from any folder, with no
# PYTHONPATH (docs/guide/python.md): installs the Debian packages the package needs
# (apt-get update first; as root), builds only its module (portalsim._core) in the build
# folder tools/setup.sh uses, and installs the package where Debian's python3 looks for
# local ones (/usr/local/lib/python3.X/dist-packages). Run again after changing the sources.
# The `python3` a pyenv puts first on PATH is another interpreter, without Debian's numpy
# and torch: call /usr/bin/python3.
set -euo pipefail
cd "$(dirname "$0")/.."
# To build the core and the module (configuring the build folder as tools/setup.sh does needs
# GoogleTest and Google Benchmark too), and to use the package: NumPy, h5py and PyTorch.
packages=(build-essential cmake ninja-build pkg-config
  pocl-opencl-icd ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers
  libopenimageio-dev libcli11-dev libtomlplusplus-dev nlohmann-json3-dev
  libxxhash-dev libisal-dev libgtest-dev libbenchmark-dev libcpp-httplib-dev libhdf5-dev libboost-dev
  python3 python3-dev pybind11-dev python3-pybind11 python3-numpy python3-h5py python3-torch python3-pytest python3-pil)
bash tools/apt-install.sh "${packages[@]}"

build_dir=${PORTALSIM_BUILD_DIR:-build}
generator=()
[ -f "$build_dir/CMakeCache.txt" ] || ! command -v ninja >/dev/null || generator=(-G Ninja)
cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DPORTALSIM_PYTHON=ON \
  ${PORTALSIM_CMAKE_ARGS:-} >/dev/null
cmake --build "$build_dir" -j "$(nproc)" --target portalsim_python
cmake --install "$build_dir" --component python
cd /
/usr/bin/python3 -c "import portalsim; print('portalsim', portalsim.__version__, 'for', __import__('sys').executable, 'in', portalsim.__path__[0])"
