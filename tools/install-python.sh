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
# The core and the module (configuring the build folder as tools/setup.sh does), and NumPy,
# h5py and PyTorch to use the package.
source tools/packages.sh
bash tools/apt-install.sh "${core_packages[@]}" "${python_packages[@]}"

build_dir=${PORTALSIM_BUILD_DIR:-build}
generator=()
[ -f "$build_dir/CMakeCache.txt" ] || ! command -v ninja >/dev/null || generator=(-G Ninja)
cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DPORTALSIM_PYTHON=ON \
  ${PORTALSIM_CMAKE_ARGS:-} >/dev/null
cmake --build "$build_dir" -j "$(nproc)" --target portalsim_python
cmake --install "$build_dir" --component python
cd /
/usr/bin/python3 -c "import portalsim; print('portalsim', portalsim.__version__, 'for', __import__('sys').executable, 'in', portalsim.__path__[0])"
