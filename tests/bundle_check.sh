#!/usr/bin/env bash
# ctest bundle.minimal_root: tools/bundle.sh's tarball, unpacked into a bare Debian 12 root
# (debootstrap --variant=minbase, no build packages), must run simulate and generate with
# --backend reference and no OpenCL driver, then on the OpenCL backend once Debian's
# pocl-opencl-icd alone is installed, each byte for byte as the build's own binary outside;
# and its Python package must import under the root's /usr/bin/python3 and give the build's
# arrays. As root (chroot, mounts); the roots are made once (Debian's mirror) and cached.
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

# The roots: "base" (minbase + python3-numpy) and "pocl" (base + pocl-opencl-icd), made with
# the host's apt sources so that PoCL is the host's version. Each is made in a temporary
# folder and renamed when complete, under a lock, so a cut-off run leaves no half root.
cache=${PORTALSIM_ROOT_CACHE:-/var/cache/portalsim}/bookworm-minbase-v1
mkdir -p "$cache"
exec 9>"$cache/.lock"
flock 9
in_root() { local root=$1; shift; chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin LC_ALL=C.UTF-8 "$@"; }
apt_in_root() {
  in_root "$1" apt-get update -q >/dev/null
  in_root "$1" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${@:2}" >/dev/null
  in_root "$1" apt-get clean
}
if [ ! -d "$cache/base" ]; then
  echo "bundle_check: making the minimal root $cache/base (debootstrap, about a minute)"
  rm -rf "$cache/base.tmp"
  debootstrap --variant=minbase bookworm "$cache/base.tmp" http://deb.debian.org/debian >"$cache/debootstrap.log" 2>&1 ||
    fail "debootstrap failed: $cache/debootstrap.log"
  rm -f "$cache/base.tmp/etc/apt/sources.list"
  cp /etc/apt/sources.list.d/debian.sources "$cache/base.tmp/etc/apt/sources.list.d/"
  cp -L /etc/resolv.conf "$cache/base.tmp/etc/resolv.conf"
  mnt "$cache/base.tmp"
  apt_in_root "$cache/base.tmp" python3-numpy
  cleanup
  mv "$cache/base.tmp" "$cache/base"
fi
if [ ! -d "$cache/pocl" ]; then
  echo "bundle_check: making $cache/pocl (the base root with pocl-opencl-icd)"
  rm -rf "$cache/pocl.tmp"
  cp -a "$cache/base" "$cache/pocl.tmp"
  mnt "$cache/pocl.tmp"
  apt_in_root "$cache/pocl.tmp" pocl-opencl-icd
  cleanup
  mv "$cache/pocl.tmp" "$cache/pocl"
fi
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
[ -f "$tarball" ] || fail "tools/bundle.sh made no $tarball"
work=$build/bundle-check
rm -rf "$work"
mkdir -p "$work/bundle" "$work/host"
tar -C "$work/bundle" -xzf "$tarball"
bundle=$work/bundle/portalsim-$version-linux-x86_64
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
run_root() {  # run_root ROOT DIR BACKEND: the bundle inside ROOT, with nothing but it on the paths
  local root=$cache/$1 dir=$work/$1-$3 backend=$3
  mkdir -p "$dir" "$root/opt/portalsim" "$root/check"
  mount --bind "$bundle" "$root/opt/portalsim" && mounts+=("$root/opt/portalsim")
  mount -o remount,bind,ro "$root/opt/portalsim"
  mount --bind "$dir" "$root/check" && mounts+=("$root/check")
  mnt "$root"
  # Every library but glibc's resolves inside the bundle.
  local ldd_out
  ldd_out=$(in_root "$root" ldd /opt/portalsim/bin/portalsim /opt/portalsim/python/portalsim/_core.cpython-311-x86_64-linux-gnu.so \
    /opt/portalsim/lib/portalsim/libportalsim_oiio.so /opt/portalsim/python/portalsim/libportalsim_oiio.so) ||
    fail "ldd failed in the $1 root"
  if grep -q 'not found' <<<"$ldd_out"; then fail "in the $1 root, libraries are missing: $(grep 'not found' <<<"$ldd_out" | tr -s ' \t' ' ')"; fi
  local outside
  outside=$(awk '$2 == "=>" && $3 !~ /^\/opt\/portalsim\// {print $1}' <<<"$ldd_out" |
    grep -v -E '^(libc|libm|libpthread|libdl|librt|libresolv|libmvec)\.so\.[0-9]+$' || true)
  [ -z "$outside" ] || fail "in the $1 root, libraries resolve outside the bundle: $outside"
  run_in() { in_root "$root" env HOME=/check/home POCL_CACHE_DIR=/check/pocl-cache PYTHONDONTWRITEBYTECODE=1 \
               sh -c 'mkdir -p "$HOME" && cd /check && "$@"' sh "$@"; }
  run_in /opt/portalsim/bin/portalsim --version >/dev/null || fail "bin/portalsim --version failed in the $1 root"
  run_in /opt/portalsim/bin/portalsim "${simulate[@]}" --backend "$backend" >/dev/null ||
    fail "simulate --backend $backend failed in the $1 root"
  run_in /opt/portalsim/bin/portalsim "${simulate_physics[@]}" --backend "$backend" >/dev/null ||
    fail "simulate --model physics --backend $backend failed in the $1 root"
  run_in /opt/portalsim/bin/portalsim "${generate[@]}" --backend "$backend" --quiet >/dev/null ||
    fail "generate --backend $backend failed in the $1 root"
  run_in env PYTHONPATH=/opt/portalsim/python /usr/bin/python3 -c "$python_code" "$backend" >"$dir/python.txt" ||
    fail "the Python package failed in the $1 root under /usr/bin/python3 ($backend)"
  cleanup
  rm -rf "$dir/home" "$dir/pocl-cache"
  diff -r "$work/host/$backend" "$dir" >"$work/$1-$3.diff" ||
    fail "the $1 root's outputs ($backend) differ from the build's: $work/$1-$3.diff"
  echo "bundle_check: $1 root, --backend $backend: $(find "$dir" -type f | wc -l) files byte-identical to the build's"
}

run_host reference reference
run_host opencl opencl
run_root base reference reference

# With no driver, the OpenCL backend must fail with a message, not crash.
mkdir -p "$cache/base/check"
mount --bind "$work/host" "$cache/base/check" && mounts+=("$cache/base/check")
mnt "$cache/base"
mount --bind "$bundle" "$cache/base/opt/portalsim" && mounts+=("$cache/base/opt/portalsim")
set +e
msg=$(in_root "$cache/base" /opt/portalsim/bin/portalsim bench --list-devices 2>&1)
rc=$?
set -e
cleanup
case $rc in
  0) fail "bench --list-devices succeeded in the base root, which has no OpenCL driver" ;;
  1|2|3|4|5) [ -n "$msg" ] || fail "bench --list-devices failed silently without a driver (exit $rc)" ;;
  *) fail "bench --list-devices crashed without a driver (exit $rc): $msg" ;;
esac
echo "bundle_check: base root, no driver: bench --list-devices exits $rc: $msg"

run_root pocl opencl opencl
mount --bind "$bundle" "$cache/pocl/opt/portalsim" && mounts+=("$cache/pocl/opt/portalsim")
mnt "$cache/pocl"
devices=$(in_root "$cache/pocl" /opt/portalsim/bin/portalsim bench --list-devices) ||
  fail "bench --list-devices failed in the pocl root"
cleanup
grep -q 'Portable Computing Language' <<<"$devices" || fail "bench --list-devices in the pocl root names no PoCL device: $devices"
echo "bundle_check: pocl root: $devices"
echo "bundle_check: passed ($(du -h "$tarball" | cut -f1) bundle)"
