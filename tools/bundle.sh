#!/usr/bin/env bash
# Makes portalsim-VERSION-linux-x86_64.tar.gz in the build folder (PORTALSIM_BUILD_DIR, default
# build): bin/portalsim, the Python package, every shared library they load but glibc's (in
# lib/, found through the RPATH $ORIGIN/../lib), and the docs. docs/guide/install.md describes it; the
# ctest bundle.minimal_root runs it in a bare Debian 12 root.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$PWD
build_dir=$(realpath -m "${PORTALSIM_BUILD_DIR:-build}")

# Its own build folder, beside the build folder (at the same depth, so that ccache, with or
# without CCACHE_BASEDIR, reuses the build folder's objects: the flags are the same), so the
# developer build keeps -march=native and its tests: here the plain loops of `bench` are
# built for x86-64-v3 (AVX2, FMA), to run on other machines.
sub=$build_dir.bundle-build
PORTALSIM_BUILD_DIR=$sub PORTALSIM_TARGET=portalsim \
  PORTALSIM_CMAKE_ARGS="-DPORTALSIM_TESTS=OFF -DPORTALSIM_BENCH=OFF -DPORTALSIM_PYTHON=ON -DPORTALSIM_SANITIZE=OFF
                        -DPORTALSIM_FUZZ=OFF -DPORTALSIM_BASELINE_MARCH=x86-64-v3" \
  bash tools/setup.sh
cmake --build "$sub" -j "$(nproc)" --target portalsim_python
for tool in patchelf strip dpkg-query objdump; do
  command -v "$tool" >/dev/null || { echo "bundle.sh: $tool is missing (tools/packages.sh lists it)" >&2; exit 1; }
done

version=$("$sub/portalsim" --version | awk '{print $NF}')
[[ $version =~ ^[0-9]+\.[0-9]+\.[0-9]+ ]] || { echo "bundle.sh: cannot read the version from portalsim --version" >&2; exit 1; }
name=portalsim-$version-linux-x86_64
stage_root=$build_dir/bundle-stage
stage=$stage_root/$name
rm -rf "$stage_root"
mkdir -p "$stage/bin" "$stage/lib/portalsim" "$stage/python/portalsim" "$stage/share/licenses" "$stage/tools"

install -m 755 "$sub/portalsim" "$stage/bin/portalsim"
core=$(find "$sub/python/portalsim" -maxdepth 1 -name '_core*.so')
[ -n "$core" ] || { echo "bundle.sh: the Python module _core*.so was not built in $sub/python/portalsim" >&2; exit 1; }
install -m 644 "$core" "$stage/python/portalsim/"
install -m 644 "$src"/python/portalsim/*.py "$stage/python/portalsim/"
# The OpenImageIO module (host/assets/oiio/codec.h), loaded when an image file is read or a
# non-PNG one written: where the binary looks for it from bin/ (lib/portalsim/, as
# `cmake --install` puts it), and beside the Python module, where the Python module looks.
oiio=$sub/libportalsim_oiio.so
[ -f "$oiio" ] || { echo "bundle.sh: the OpenImageIO module $oiio was not built" >&2; exit 1; }
install -m 644 "$oiio" "$stage/lib/portalsim/"
install -m 644 "$oiio" "$stage/python/portalsim/"

# Every library the binary and the module load, transitively (ldd), but glibc's (package
# libc6: libc, libm, libpthread, libdl, librt, ld-linux), which must be the system's own.
# libstdc++ and libgcc_s come along, so an older (>= 2.36) glibc system needs no GCC 12.
# The OpenCL ICD loader (libOpenCL.so.1) comes along; drivers are dlopened by it, never linked.
libs() {
  ldd "$stage/bin/portalsim" "$stage/python/portalsim/"_core*.so "$stage/lib/portalsim/libportalsim_oiio.so" | awk '$2 == "=>" {print $1, $3}' | sort -u
}
missing=$(libs | awk '$2 == "not" {print $1}')
[ -z "$missing" ] || { echo "bundle.sh: ldd finds no $missing" >&2; exit 1; }
# Each file's Debian package, from dpkg's file lists in one pass (merged /usr: a file may be
# listed under /lib; alternatives such as libblas.so.3: under the file the link names).
declare -A owner_of=()
candidates=$(libs | while read -r _ path; do
  real=$(realpath "$path")
  printf '%s\n' "$path" "${path#/usr}" "/usr$path" "$real" "${real#/usr}" "/usr$real"
done | sort -u)
while IFS= read -r line; do
  file=${line#*.list:}
  pkg=${line%%.list:*}
  pkg=${pkg##*/}
  owner_of[$file]=${pkg%%:*}
done < <(grep -H -x -F -e "$candidates" /var/lib/dpkg/info/*.list)
declare -A packages=()
glibc_sonames=()
while read -r soname path; do
  real=$(realpath "$path")
  pkg=
  for p in "$path" "${path#/usr}" "/usr$path" "$real" "${real#/usr}" "/usr$real"; do
    [ -z "${owner_of[$p]:-}" ] || { pkg=${owner_of[$p]}; break; }
  done
  [ -n "$pkg" ] || { echo "bundle.sh: $path belongs to no Debian package; refusing to bundle it" >&2; exit 1; }
  if [ "$pkg" = libc6 ]; then glibc_sonames+=("$soname"); continue; fi
  cp -L "$path" "$stage/lib/$soname"
  chmod 644 "$stage/lib/$soname"
  packages[$pkg]=1
done < <(libs)
[ -f "$stage/lib/libOpenCL.so.1" ] || { echo "bundle.sh: libOpenCL.so.1 (the ICD loader) is not among the libraries" >&2; exit 1; }
if compgen -G "$stage/lib/*[pP][oO][cC][lL]*" >/dev/null; then echo "bundle.sh: a PoCL library was picked up; the driver must not be bundled" >&2; exit 1; fi

# Found from wherever the bundle is unpacked: DT_RPATH (not RUNPATH) on the binary and the
# module, because the loader applies an object's RPATH to its libraries' libraries too, so
# the Debian libraries need no change. The few that carry their own RUNPATH (Open MPI's)
# would look there instead: theirs becomes $ORIGIN.
strip --strip-unneeded "$stage/bin/portalsim" "$stage/python/portalsim/"_core*.so "$stage/lib/portalsim/libportalsim_oiio.so" \
  "$stage/python/portalsim/libportalsim_oiio.so"
patchelf --force-rpath --set-rpath '$ORIGIN/../lib' "$stage/bin/portalsim"
patchelf --force-rpath --set-rpath '$ORIGIN/../../lib' "$stage/python/portalsim/"_core*.so \
  "$stage/python/portalsim/libportalsim_oiio.so"
patchelf --force-rpath --set-rpath '$ORIGIN/..' "$stage/lib/portalsim/libportalsim_oiio.so"
for lib in "$stage"/lib/*; do
  [ -f "$lib" ] || continue
  [ -z "$(patchelf --print-rpath "$lib")" ] || patchelf --set-rpath '$ORIGIN' "$lib"
done

# Each bundled library's copyright file, from its Debian package.
for pkg in "${!packages[@]}"; do
  if [ -f "/usr/share/doc/$pkg/copyright" ]; then
    mkdir -p "$stage/share/licenses/$pkg"
    cp "/usr/share/doc/$pkg/copyright" "$stage/share/licenses/$pkg/"
  fi
done

# Every library now resolves inside the bundle, or is glibc's.
stray=$(libs | while read -r soname path; do
  case "$(realpath -m "$path")" in "$stage"/lib/*) continue ;; esac
  [[ " ${glibc_sonames[*]} " == *" $soname "* ]] || echo "$soname => $path"
done)
[ -z "$stray" ] || { printf 'bundle.sh: libraries resolved outside the bundle:\n%s\n' "$stray" >&2; exit 1; }
glibc=$(objdump -T "$stage/bin/portalsim" "$stage/python/portalsim/"_core*.so "$stage"/lib/*.so* "$stage"/lib/portalsim/*.so 2>/dev/null |
  grep -o 'GLIBC_[0-9][0-9.]*' | sort -u -V | tail -n1)

cp -r "$src/docs" "$stage/docs"
install -m 755 "$src/tools/device-check.sh" "$stage/tools/device-check.sh"
commit=$(git -C "$src" rev-parse --short HEAD 2>/dev/null || echo unknown)
cat >"$stage/README.md" <<EOF
# portalsim $version for Linux x86-64

Built from commit \`$commit\` on Debian 12. Unpack anywhere and run:

\`\`\`sh
bin/portalsim --help
bin/portalsim simulate --backend reference none none none gun --out gun   # no OpenCL driver needed
bin/portalsim bench --list-devices                                       # the OpenCL devices found
PYTHONPATH=\$PWD/python python3.11 -c "import portalsim; print(portalsim.__version__)"
\`\`\`

- \`bin/portalsim\`: the simulator; its kernels and built-in catalogue are inside it.
- \`lib/\`: the libraries it and the Python module load, but glibc's (\`lib/portalsim/\`: its
  OpenImageIO module, loaded only to read image files or write other formats than PNG); the newest glibc symbol
  version they need is $glibc. It includes the OpenCL ICD loader (libOpenCL.so.1), not a driver:
  the OpenCL backend (the default) uses the drivers that /etc/OpenCL/vendors/*.icd (or
  OCL_ICD_VENDORS) names. \`--backend reference\` needs none.
- \`python/portalsim/\`: the Python package, for CPython 3.11 with NumPy.
- \`tools/device-check.sh OUTDIR\`: checks an OpenCL device (a GPU) against the CPU.
- \`share/licenses/\`: the Debian copyright file of each bundled library.
- \`docs/\`: the guides; start with [install](docs/guide/install.md) and
  [the command line](docs/reference/command-line.md).
EOF

# Reproducible: sorted names, no owners, the commit's time.
mtime=$(git -C "$src" log -1 --format=%ct 2>/dev/null || date +%s)
out=$build_dir/$name.tar.gz
tar -C "$stage_root" --sort=name --owner=0 --group=0 --numeric-owner --mtime="@$mtime" -cf - "$name" |
  gzip -n >"$out.tmp"
mv "$out.tmp" "$out"
echo "bundle.sh: $out ($(du -h "$out" | cut -f1), unpacked $(du -sh "$stage" | cut -f1); needs glibc >= ${glibc#GLIBC_})"
