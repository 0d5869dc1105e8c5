#!/usr/bin/env bash
# Makes portalsim-VERSION-linux-x86_64.tar.gz in the build folder (PORTALSIM_BUILD_DIR, default
# build): bin/portalsim, the Python package, every shared library they load but glibc's and
# the C++ runtime's (in lib/, found through the RPATH $ORIGIN/../lib), and the docs; and its
# images add-on, portalsim-VERSION-linux-x86_64-images.tar.gz: the OpenImageIO module and the
# libraries only it loads. docs/guide/install.md describes them; the ctest
# bundle.minimal_root runs them in bare Debian 12 and 13 roots.
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
# The MPI module (host/schedule/mpi/comm.h), loaded only under an MPI launcher. It links the
# system's Open MPI (libmpi.so.40), the launcher's own, whose plugins must match it: no MPI
# library is bundled, and the module's libraries are left out of the scan below.
mpi_module=$sub/libportalsim_mpi.so
[ -f "$mpi_module" ] || { echo "bundle.sh: the MPI module $mpi_module was not built (libopenmpi-dev)" >&2; exit 1; }
install -m 644 "$mpi_module" "$stage/lib/portalsim/"

# Every library the binary and the modules load, transitively (ldd), but glibc's (package
# libc6: libc, libm, libpthread, libdl, librt, ld-linux) and the C++ runtime's (libstdc++6,
# libgcc-s1), which must be the system's own: an OpenCL driver is loaded into the process
# and brings its own needs of the C++ runtime (Debian 13's PoCL 6 needs GCC 14's
# GLIBCXX_3.4.32), and a bundled older libstdc++ found first through the RPATH kept it from
# loading. The system's is always at least as new as the build's on a system whose glibc is
# new enough (docs/guide/install.md); lib/fallback/ holds the build's copy for one without.
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
declare -A packages=() package_of=()
system_sonames=() fallback=()
while read -r soname path; do
  real=$(realpath "$path")
  pkg=
  for p in "$path" "${path#/usr}" "/usr$path" "$real" "${real#/usr}" "/usr$real"; do
    [ -z "${owner_of[$p]:-}" ] || { pkg=${owner_of[$p]}; break; }
  done
  [ -n "$pkg" ] || { echo "bundle.sh: $path belongs to no Debian package; refusing to bundle it" >&2; exit 1; }
  case $pkg in
    libc6) system_sonames+=("$soname"); continue ;;
    libstdc++6 | libgcc-s1) system_sonames+=("$soname"); fallback+=("$path") ;;
    *) install -m 644 "$(realpath "$path")" "$stage/lib/$soname" ;;
  esac
  packages[$pkg]=1
  package_of[$soname]=$pkg
done < <(libs)
mkdir -p "$stage/lib/fallback"
for path in "${fallback[@]}"; do install -m 644 "$(realpath "$path")" "$stage/lib/fallback/$(basename "$path")"; done
[ -f "$stage/lib/libOpenCL.so.1" ] || { echo "bundle.sh: libOpenCL.so.1 (the ICD loader) is not among the libraries" >&2; exit 1; }
if compgen -G "$stage/lib/*[pP][oO][cC][lL]*" >/dev/null; then echo "bundle.sh: a PoCL library was picked up; the driver must not be bundled" >&2; exit 1; fi

# Found from wherever the bundle is unpacked: DT_RPATH (not RUNPATH) on the binary and the
# module, because the loader applies an object's RPATH to its libraries' libraries too, so
# the Debian libraries need no change. The few that carry their own RUNPATH (Open MPI's)
# would look there instead: theirs becomes $ORIGIN.
strip --strip-unneeded "$stage/bin/portalsim" "$stage/python/portalsim/"_core*.so "$stage"/lib/portalsim/*.so \
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

# Every library now resolves inside the bundle, or is glibc's or the C++ runtime's.
stray=$(libs | while read -r soname path; do
  case "$(realpath -m "$path")" in "$stage"/lib/*) continue ;; esac
  [[ " ${system_sonames[*]} " == *" $soname "* ]] || echo "$soname => $path"
done)
[ -z "$stray" ] || { printf 'bundle.sh: libraries resolved outside the bundle:\n%s\n' "$stray" >&2; exit 1; }
newest() {  # newest PREFIX: the newest symbol version of that prefix the bundle needs
  objdump -T "$stage/bin/portalsim" "$stage/python/portalsim/"_core*.so "$stage"/lib/*.so* "$stage"/lib/portalsim/*.so 2>/dev/null |
    grep -o "$1_[0-9][0-9.]*" | sort -u -V | tail -n1
}
glibc=$(newest GLIBC)
glibcxx=$(newest GLIBCXX)

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
- \`lib/\`: the libraries it and the Python module load, but glibc's and the C++ runtime's
  (libstdc++, libgcc_s), which are the system's own (\`lib/portalsim/\`: its MPI module, loaded
  only under mpirun, which uses the system's Open MPI). The newest symbol versions they need
  are $glibc and $glibcxx (GCC 12's libstdc++); \`lib/fallback/\` holds that libstdc++ for a
  system without one: \`LD_LIBRARY_PATH=\$PWD/lib/fallback\`. It includes the OpenCL ICD loader (libOpenCL.so.1), not a driver:
  the OpenCL backend (the default) uses the drivers that /etc/OpenCL/vendors/*.icd (or
  OCL_ICD_VENDORS) names. \`--backend reference\` needs none.
- \`python/portalsim/\`: the Python package, for CPython 3.11 with NumPy.
- The images add-on, \`$name-images.tar.gz\`, unpacked over this folder, adds
  OpenImageIO's module (\`lib/portalsim/libportalsim_oiio.so\`) and its libraries: a run needs
  it only to read image files (a catalogue's own images, captures for \`features\`,
  \`validate\` and \`calibrate\`) or to write JPEG; without it such a run stops and says so.
- \`tools/device-check.sh OUTDIR\`: checks an OpenCL device (a GPU) against the CPU.
- \`share/licenses/\`: the Debian copyright file of each bundled library.
- \`docs/\`: the guides; start with [install](docs/guide/install.md) and
  [the command line](docs/reference/command-line.md).
EOF

# Two tarballs. The images add-on holds the OpenImageIO module and the libraries only it
# loads (FFmpeg, OpenCV, GDAL, OpenVDB...: Debian's OpenImageIO links every codec it was built
# with, and binds them all at load), which a run needs only to read image files, resize them
# or write JPEG; the bundle holds the rest, and the add-on is unpacked over it.
core_sonames=$(ldd "$stage/bin/portalsim" "$stage/python/portalsim/"_core*.so | awk '$2 == "=>" {print $1}' | sort -u)
declare -A core_packages=()
for soname in $core_sonames; do [ -z "${package_of[$soname]:-}" ] || core_packages[${package_of[$soname]}]=1; done
images=("$name/lib/portalsim/libportalsim_oiio.so" "$name/python/portalsim/libportalsim_oiio.so")
for lib in "$stage"/lib/*.so*; do
  soname=${lib##*/}
  grep -qxF "$soname" <<<"$core_sonames" && continue
  images+=("$name/lib/$soname")
  pkg=${package_of[$soname]}
  [ -n "${core_packages[$pkg]:-}" ] || [ ! -d "$stage/share/licenses/$pkg" ] || images+=("$name/share/licenses/$pkg/copyright")
done
(cd "$stage_root" && find "$name" -type f | LC_ALL=C sort) >"$stage_root/all.list"
printf '%s\n' "${images[@]}" | LC_ALL=C sort -u >"$stage_root/images.list"
LC_ALL=C comm -23 "$stage_root/all.list" "$stage_root/images.list" >"$stage_root/core.list"
# Reproducible: sorted names, no owners, the commit's time.
mtime=$(git -C "$src" log -1 --format=%ct 2>/dev/null || date +%s)
pack() {  # pack LIST OUT
  tar -C "$stage_root" --owner=0 --group=0 --numeric-owner --mtime="@$mtime" -cf - -T "$1" | gzip -n >"$2.tmp"
  mv "$2.tmp" "$2"
}
out=$build_dir/$name.tar.gz
out_images=$build_dir/$name-images.tar.gz
pack "$stage_root/core.list" "$out"
pack "$stage_root/images.list" "$out_images"
mib() { echo "$(( ($(stat -c %s "$1") + 524288) / 1048576 )) MiB"; }
echo "bundle.sh: $out ($(mib "$out"), $(wc -l <"$stage_root/core.list") files) and its images add-on $out_images ($(mib "$out_images"), $(wc -l <"$stage_root/images.list") files); unpacked together $(du -sh "$stage" | cut -f1); needs glibc >= ${glibc#GLIBC_} and libstdc++ with $glibcxx"
