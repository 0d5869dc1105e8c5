#!/usr/bin/env bash
# ctest bundle.minimal_root: tools/bundle.sh's tarball, unpacked into bare roots
# (debootstrap --variant=minbase, no build packages), byte for byte as the build's own binary
# outside:
# - Debian 12: simulate and generate with --backend reference and no OpenCL driver, then on
#   the OpenCL backend once Debian's pocl-opencl-icd alone is installed; its Python package
#   under the root's /usr/bin/python3 gives the build's arrays;
# - Debian 13 (glibc 2.41, GCC 14's libstdc++) with its pocl-opencl-icd (PoCL 6, LLVM 18):
#   the same commands on the OpenCL backend, the driver loaded next to the bundle's
#   libraries; its Python (3.13) refuses the 3.11 module with a message that says so;
# - Debian 12 and 13 with openmpi-bin: `mpirun -np 2` of the bundle's binary, under the
#   root's own Open MPI (4.1, 5.0), equals one process;
# - an OpenCL driver that does not load is named with the loader's reason.
# As root (chroot, mounts); the roots are made once (Debian's mirror) and cached, and get
# /proc, /sys and /dev mounted as a real machine has them.
# Usage: bundle_check.sh SOURCE_DIR BUILD_DIR PORTALSIM
set -euo pipefail
fail() { echo "bundle_check: $*" >&2; exit 1; }
[ $# -eq 3 ] || fail "usage: bundle_check.sh SOURCE_DIR BUILD_DIR PORTALSIM"
src=$(realpath "$1") build=$(realpath "$2") host_bin=$(realpath "$3")
[ "$(id -u)" = 0 ] || fail "needs root (chroot and mounts)"
for tool in debootstrap chroot unshare flock mount; do
  command -v "$tool" >/dev/null || fail "$tool is missing (tools/packages.sh lists debootstrap)"
done
for f in /etc/apt/sources.list.d/debian.sources /etc/resolv.conf; do
  [ -f "$f" ] || fail "$f is missing: the roots take the host's Debian sources and name server"
done

# A private mount namespace: whatever is mounted below goes away with this process, even if
# the trap's unmounts are cut short.
if [ -z "${BUNDLE_CHECK_UNSHARED:-}" ]; then
  exec env BUNDLE_CHECK_UNSHARED=1 unshare --mount --propagation private bash "$0" "$@"
fi

mounts=()
cleanup() {
  local i
  for ((i = ${#mounts[@]} - 1; i >= 0; i--)); do umount -l "${mounts[i]}" 2>/dev/null || true; done
  mounts=()
}
trap cleanup EXIT
mnt() {  # mnt ROOT: /proc and /dev for apt and the runs, /sys for PoCL (hwloc reads the CPUs there)
  mount -t proc proc "$1/proc" && mounts+=("$1/proc")
  mount --rbind /dev "$1/dev" && mounts+=("$1/dev")
  mount --rbind /sys "$1/sys" && mounts+=("$1/sys")
}

# The roots, each made in a temporary folder and renamed when complete, under a lock, so a
# cut-off run leaves no half root. Debian 12's: "base" (minbase + python3-numpy), "pocl"
# (base + pocl-opencl-icd) and "mpi" (base + openmpi-bin), made with the host's apt sources so
# that PoCL is the host's version; Debian 13's: "pocl" (minbase + python3 + pocl-opencl-icd)
# and "mpi" (that + openmpi-bin), from the same mirror.
cache_root=${PORTALSIM_ROOT_CACHE:-/var/cache/portalsim}
cache=$cache_root/bookworm-minbase-v1
trixie=$cache_root/trixie-minbase-v1/pocl trixie_mpi=$cache_root/trixie-minbase-v1/mpi
mkdir -p "$cache" "${trixie%/*}"
exec 9>"$cache_root/.lock"
flock 9
in_root() { local root=$1; shift; chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin LC_ALL=C.UTF-8 "$@"; }
apt_in_root() {
  in_root "$1" apt-get update -q >/dev/null
  in_root "$1" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${@:2}" >/dev/null
  in_root "$1" apt-get clean
}
bootstrap() {  # bootstrap SUITE ROOT: a minbase root of SUITE in ROOT.tmp
  local suite=$1 root=$2
  echo "bundle_check: making the minimal $suite root $root (debootstrap, a minute or two)"
  rm -rf "$root.tmp"
  debootstrap --variant=minbase "$suite" "$root.tmp" http://deb.debian.org/debian >"$root.debootstrap.log" 2>&1 ||
    fail "debootstrap failed: $root.debootstrap.log"
  cp -L /etc/resolv.conf "$root.tmp/etc/resolv.conf"
}
derive() {  # derive FROM NAME PACKAGES...: the root FROM with PACKAGES installed, as NAME
  local from=$1 root=$2
  [ ! -d "$root" ] || return 0
  echo "bundle_check: making $root (${*:3})"
  rm -rf "$root.tmp"
  cp -a "$from" "$root.tmp"
  mnt "$root.tmp"
  apt_in_root "$root.tmp" "${@:3}"
  cleanup
  mv "$root.tmp" "$root"
}
if [ ! -d "$cache/base" ]; then
  bootstrap bookworm "$cache/base"
  rm -f "$cache/base.tmp/etc/apt/sources.list"
  cp /etc/apt/sources.list.d/debian.sources "$cache/base.tmp/etc/apt/sources.list.d/"
  mnt "$cache/base.tmp"
  apt_in_root "$cache/base.tmp" python3-numpy
  cleanup
  mv "$cache/base.tmp" "$cache/base"
fi
derive "$cache/base" "$cache/pocl" pocl-opencl-icd
derive "$cache/base" "$cache/mpi" openmpi-bin
if [ ! -d "$trixie" ]; then
  bootstrap trixie "$trixie"
  mnt "$trixie.tmp"
  apt_in_root "$trixie.tmp" python3-minimal pocl-opencl-icd
  cleanup
  mv "$trixie.tmp" "$trixie"
fi
derive "$trixie" "$trixie_mpi" openmpi-bin
flock -u 9

# The base root has no OpenCL at all, and neither root any of the build's libraries or
# -dev packages but what PoCL itself depends on (clang-15's headers).
[ ! -e "$cache/base/etc/OpenCL" ] || fail "the base root has /etc/OpenCL: it must have no OpenCL driver"
for root in base pocl; do
  for pkg in ocl-icd-libopencl1 libopenimageio2.4 libhdf5-103-1 libopenmpi3 ocl-icd-opencl-dev libopenimageio-dev \
             pybind11-dev python3-dev cmake g++; do
    if in_root "$cache/$root" dpkg-query -W -f '${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed'; then
      fail "the $root root has $pkg installed: it must have none of the build's packages"
    fi
  done
done
devs=$(in_root "$cache/base" dpkg-query -W -f '${Package}\n' | grep -- '-dev$' || true)
[ -z "$devs" ] || fail "the base root has -dev packages: $devs"
[ -f "$cache/pocl/etc/OpenCL/vendors/pocl.icd" ] || fail "the pocl root has no /etc/OpenCL/vendors/pocl.icd"

# The bundle, made from these sources in this build folder.
PORTALSIM_BUILD_DIR=$build bash "$src/tools/bundle.sh"
version=$("$host_bin" --version | awk '{print $NF}')
tarball=$build/portalsim-$version-linux-x86_64.tar.gz
images_tarball=$build/portalsim-$version-linux-x86_64-images.tar.gz
[ -f "$tarball" ] || fail "tools/bundle.sh made no $tarball"
[ -f "$images_tarball" ] || fail "tools/bundle.sh made no images add-on $images_tarball"
work=$build/bundle-check
rm -rf "$work"
mkdir -p "$work/bundle" "$work/host"
tar -C "$work/bundle" -xzf "$tarball"
bundle=$work/bundle/portalsim-$version-linux-x86_64
# The bundle alone holds no OpenImageIO: its module and libraries are the add-on's.
for f in lib/portalsim/libportalsim_oiio.so python/portalsim/libportalsim_oiio.so lib/libOpenImageIO.so.2.4; do
  [ ! -e "$bundle/$f" ] || fail "the bundle holds $f, which belongs to its images add-on"
done
[ -x "$bundle/bin/portalsim" ] || fail "the tarball has no bin/portalsim"
[ -d "$build/python/portalsim" ] || fail "$build/python/portalsim is missing: build the target portalsim_python"

# The commands, run from an empty folder both outside (the build's binary) and inside.
simulate=(simulate --seed 7 --out simulate none none none gun)
# JPEG, so that the OpenImageIO module (lib/portalsim/) is loaded and writes them.
simulate_physics=(simulate --seed 7 --model physics --image-format jpg --out simulate-physics none Mobile none none none cd)
generate=(generate --count 120 --seed 5 --what both --format arff,csv,npy,h5 --annotations --out generate)
python_code='
import hashlib, sys, portalsim
backend = sys.argv[1]
gen = portalsim.Generator(seed=3, what="both", annotations=True, backend=backend)
b = gen.batch(start=0, count=16)
h = hashlib.sha256()
for k in sorted(b):
    h.update(k.encode()); h.update(str(b[k].dtype).encode()); h.update(b[k].tobytes())
print(portalsim.__version__, h.hexdigest())
'
run_host() {  # run_host DIR BACKEND: the build's binary and module, outside
  local dir=$work/host/$1 backend=$2
  mkdir -p "$dir"
  (cd "$dir" && "$host_bin" "${simulate[@]}" --backend "$backend" >/dev/null &&
    "$host_bin" "${simulate_physics[@]}" --backend "$backend" >/dev/null &&
    "$host_bin" "${generate[@]}" --backend "$backend" --quiet >/dev/null &&
    PYTHONPATH=$build/python /usr/bin/python3 -c "$python_code" "$backend" >python.txt) ||
    fail "the build's own portalsim failed outside the root ($backend)"
}
run_root() {  # run_root LABEL ROOT BACKEND PYTHON: the bundle inside ROOT, with nothing but it on the paths;
  # PYTHON "same": the package gives the build's arrays; "refused": it says it needs CPython 3.11
  local label=$1 root=$2 backend=$3 python=$4
  local dir=$work/$label-$backend
  mkdir -p "$dir" "$root/opt/portalsim" "$root/check"
  mount --bind "$bundle" "$root/opt/portalsim" && mounts+=("$root/opt/portalsim")
  mount -o remount,bind,ro "$root/opt/portalsim"
  mount --bind "$dir" "$root/check" && mounts+=("$root/check")
  mnt "$root"
  # Every library but glibc's and the C++ runtime's resolves inside the bundle.
  local ldd_out
  ldd_out=$(in_root "$root" ldd /opt/portalsim/bin/portalsim /opt/portalsim/python/portalsim/_core.cpython-311-x86_64-linux-gnu.so \
    /opt/portalsim/lib/portalsim/libportalsim_oiio.so /opt/portalsim/python/portalsim/libportalsim_oiio.so) ||
    fail "ldd failed in the $label root"
  if grep -q 'not found' <<<"$ldd_out"; then fail "in the $label root, libraries are missing: $(grep 'not found' <<<"$ldd_out" | tr -s ' \t' ' ')"; fi
  local outside
  outside=$(awk '$2 == "=>" && $3 !~ /^\/opt\/portalsim\// {print $1}' <<<"$ldd_out" |
    grep -v -E '^(libc|libm|libpthread|libdl|librt|libresolv|libmvec|libstdc\+\+|libgcc_s)\.so\.[0-9]+$' || true)
  [ -z "$outside" ] || fail "in the $label root, libraries resolve outside the bundle: $outside"
  run_in() { in_root "$root" env HOME=/check/home POCL_CACHE_DIR=/check/pocl-cache PYTHONDONTWRITEBYTECODE=1 \
               sh -c 'mkdir -p "$HOME" && cd /check && "$@"' sh "$@"; }
  run_in /opt/portalsim/bin/portalsim --version >/dev/null || fail "bin/portalsim --version failed in the $label root"
  run_in /opt/portalsim/bin/portalsim "${simulate[@]}" --backend "$backend" >/dev/null ||
    fail "simulate --backend $backend failed in the $label root"
  run_in /opt/portalsim/bin/portalsim "${simulate_physics[@]}" --backend "$backend" >/dev/null ||
    fail "simulate --model physics --backend $backend failed in the $label root"
  run_in /opt/portalsim/bin/portalsim "${generate[@]}" --backend "$backend" --quiet >/dev/null ||
    fail "generate --backend $backend failed in the $label root"
  if [ "$python" = same ]; then
    run_in env PYTHONPATH=/opt/portalsim/python /usr/bin/python3 -c "$python_code" "$backend" >"$dir/python.txt" ||
      fail "the Python package failed in the $label root under /usr/bin/python3 ($backend)"
  else
    local refusal
    refusal=$(run_in env PYTHONPATH=/opt/portalsim/python /usr/bin/python3 -c 'import portalsim' 2>&1) &&
      fail "the Python package imported in the $label root, whose Python is not 3.11"
    grep -q "was built for another Python than this one" <<<"$refusal" ||
      fail "in the $label root, the Python package's refusal does not say why: $refusal"
    echo "bundle_check: $label root: import portalsim says: $(tail -n1 <<<"$refusal")"
    cp "$work/host/$backend/python.txt" "$dir/python.txt"  # not made here: the comparison below skips it
  fi
  cleanup
  rm -rf "$dir/home" "$dir/pocl-cache"
  diff -r "$work/host/$backend" "$dir" >"$work/$label-$backend.diff" ||
    fail "the $label root's outputs ($backend) differ from the build's: $work/$label-$backend.diff"
  echo "bundle_check: $label root, --backend $backend: $(find "$dir" -type f | wc -l) files byte-identical to the build's"
}

# in_mounted ROOT DIR COMMAND...: COMMAND in ROOT, in DIR mounted at /check, with the bundle
# at /opt/portalsim; prints its output; returns its status.
in_mounted() {
  local root=$1 dir=$2 rc=0 out
  shift 2
  mkdir -p "$root/check" "$root/opt/portalsim"
  mount --bind "$dir" "$root/check" && mounts+=("$root/check")
  mount --bind "$bundle" "$root/opt/portalsim" && mounts+=("$root/opt/portalsim")
  mnt "$root"
  out=$(in_root "$root" sh -c 'cd /check && "$@"' sh "$@" 2>&1) || rc=$?
  cleanup
  printf '%s\n' "$out"
  return $rc
}

run_host reference reference
run_host opencl opencl

# The bundle without its images add-on: the built-in catalogue's PNG images are the build's;
# a JPEG stops with exit 5 and names the add-on.
mkdir -p "$work/core-only"
in_mounted "$cache/base" "$work/core-only" /opt/portalsim/bin/portalsim "${simulate[@]}" --backend reference >/dev/null ||
  fail "simulate failed in the base root without the images add-on"
diff -r "$work/host/reference/simulate" "$work/core-only/simulate" >"$work/core-only.diff" ||
  fail "without the images add-on, simulate differs from the build's: $work/core-only.diff"
set +e
msg=$(in_mounted "$cache/base" "$work/core-only" /opt/portalsim/bin/portalsim "${simulate_physics[@]}" --backend reference)
rc=$?
set -e
[ "$rc" = 5 ] && grep -q "images add-on, portalsim-$version-linux-x86_64-images.tar.gz" <<<"$msg" ||
  fail "a JPEG without the images add-on exits $rc and does not name the add-on: $msg"
echo "bundle_check: base root, no images add-on: PNG byte-identical; JPEG exits 5: $msg"
tar -C "$work/bundle" -xzf "$images_tarball"

run_root base "$cache/base" reference same

# With no driver, the OpenCL backend must fail with a message, not crash, and say what to install.
set +e
msg=$(in_mounted "$cache/base" "$work/host" /opt/portalsim/bin/portalsim bench --list-devices)
rc=$?
set -e
case $rc in
  0) fail "bench --list-devices succeeded in the base root, which has no OpenCL driver" ;;
  1|2|3|4|5) grep -q "no OpenCL driver is installed" <<<"$msg" || fail "bench --list-devices without a driver (exit $rc) does not say that none is installed: $msg" ;;
  *) fail "bench --list-devices crashed without a driver (exit $rc): $msg" ;;
esac
echo "bundle_check: base root, no driver: bench --list-devices exits $rc: $msg"

run_root pocl "$cache/pocl" opencl same
devices=$(in_mounted "$cache/pocl" "$work/host" /opt/portalsim/bin/portalsim bench --list-devices) ||
  fail "bench --list-devices failed in the pocl root: $devices"
grep -q 'Portable Computing Language' <<<"$devices" || fail "bench --list-devices in the pocl root names no PoCL device: $devices"
echo "bundle_check: pocl root: $devices"

# Debian 13: its PoCL 6 needs GCC 14's libstdc++, which the bundle must leave to the system.
run_root trixie "$trixie" opencl refused
devices=$(in_mounted "$trixie" "$work/host" /opt/portalsim/bin/portalsim bench --list-devices) ||
  fail "bench --list-devices failed in the Debian 13 root: $devices"
grep -q 'Portable Computing Language' <<<"$devices" || fail "bench --list-devices in the Debian 13 root names no PoCL device: $devices"
echo "bundle_check: Debian 13 root: $devices"
# A driver that does not load (here a bundled libstdc++ older than the one it needs, as the
# bundle once had) is named with the loader's reason, not mistaken for no driver.
set +e
msg=$(in_mounted "$trixie" "$work/host" env LD_LIBRARY_PATH=/opt/portalsim/lib/fallback /opt/portalsim/bin/portalsim bench --list-devices)
rc=$?
set -e
[ "$rc" = 5 ] || fail "with an older libstdc++ first, bench --list-devices in the Debian 13 root exits $rc, not 5: $msg"
grep -q "pocl.icd names libpocl.so.2.*, which does not load: .*GLIBCXX_3.4.3[0-9]' not found" <<<"$msg" ||
  fail "with an older libstdc++ first, the message does not name the driver and the loader's reason: $msg"
echo "bundle_check: Debian 13 root, GCC 12's libstdc++ first: $msg"

# MPI: the root's own mpirun (Open MPI 4.1 in Debian 12, 5.0 in Debian 13) starts two ranks
# of the bundle's binary, which load the MPI module and through it the root's Open MPI; the
# folder equals one process's, byte for byte.
mpi_generate=(/opt/portalsim/bin/portalsim generate --count 120 --seed 5 --what both --format arff,csv,npy,h5 --backend reference)
check_mpi() {  # check_mpi LABEL ROOT
  local label=$1 root=$2 dir=$work/$1 out
  mkdir -p "$dir" "$root/check" "$root/opt/portalsim"
  mount --bind "$bundle" "$root/opt/portalsim" && mounts+=("$root/opt/portalsim")
  mount --bind "$dir" "$root/check" && mounts+=("$root/check")
  mnt "$root"
  out=$(in_root "$root" env HOME=/check sh -c 'cd /check && "$@" --quiet --out one &&
    mpirun --allow-run-as-root --oversubscribe -np 2 "$@" --out two' sh "${mpi_generate[@]}" 2>&1) ||
    { cleanup; fail "generate, or mpirun -np 2 of it, failed in the $label root: $out"; }
  cleanup
  grep -q "2 ranks" <<<"$out" || fail "mpirun -np 2 in the $label root did not run as 2 ranks: $out"
  diff -r "$dir/one" "$dir/two" >"$work/$label.diff" || fail "mpirun -np 2 in the $label root differs from one process: $work/$label.diff"
  echo "bundle_check: $label root (Open MPI $(in_root "$root" dpkg-query -W -f '${Version}' openmpi-bin)): mpirun -np 2 equals one process ($(find "$dir/two" -type f | wc -l) files)"
}
check_mpi mpi "$cache/mpi"
check_mpi trixie-mpi "$trixie_mpi"
echo "bundle_check: passed ($(du -h "$tarball" | cut -f1) bundle)"
