# The Debian 12 packages portalsim needs, in one place: sourced by tools/setup.sh (all of
# them) and tools/install-python.sh (the core and the Python module's).
# To configure and build the core (the build folder also needs GoogleTest and Google Benchmark).
core_packages=(build-essential cmake ninja-build pkg-config
  pocl-opencl-icd ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers
  libopenimageio-dev libcli11-dev libtomlplusplus-dev nlohmann-json3-dev
  libxxhash-dev libisal-dev libgtest-dev libbenchmark-dev libcpp-httplib-dev libhdf5-dev libboost-dev libxgboost-dev)
# The Python package: its module (pybind11) and what it hands arrays to (NumPy, h5py, PyTorch).
python_packages=(python3 python3-dev pybind11-dev python3-pybind11 python3-numpy python3-h5py python3-torch
  python3-pytest python3-pil)
# The rest of the tests and tools: clinfo, oiiotool, MPI and Slurm, WEKA, the figures' and
# dataset card's Python, cram (the guides' examples run as tests), clang-format, ccache,
# the sanitizers' and fuzzers' clang, Chromium, and tools/bundle.sh's patchelf and the
# minimal root of its test (debootstrap).
tool_packages=(clinfo openimageio-tools openmpi-bin libopenmpi-dev slurm-wlm munge
  weka default-jdk-headless python3-matplotlib python3-scipy python3-pyld python3-yaml python3-cram python3-sklearn
  clang-format ccache clang libclang-rt-14-dev chromium patchelf debootstrap)
