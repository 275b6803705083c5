#!/usr/bin/env bash
# getme set-up for a fresh Debian 12 machine (run as root).
#   bash scripts/setup.sh demo   install what is missing, build, smooth the
#                                bundled example mesh, print quality before/after
#   bash scripts/setup.sh test   install what is missing, build, run all tests
#                                (normal build, ASan+UBSan build, then a
#                                core-only build: no Gmsh, CGNS, Python)
#   bash scripts/setup.sh build  install what is missing and build only
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-demo}
jobs=$(nproc 2>/dev/null || echo 2)

# Everything getme needs, from Debian 12's archive and nowhere else.
PACKAGES="cmake make gcc libc6-dev libgmsh-dev gmsh python3-gmsh libcgns-dev cgns-convert \
libhdf5-dev calculix-ccx python3 python3-numpy python3-meshio python3-h5py python3-matplotlib \
xvfb xdotool x11-apps imagemagick time python3-netgen occt-misc gmsh-doc \
calculix-ccx-test libopenmpi-dev openmpi-bin libmetis-dev"

missing=""
for p in $PACKAGES; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "Info    : installing Debian packages:$missing"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends $missing >/dev/null
fi

build() { # build DIR [cmake args...]
  local dir=$1; shift
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
  cmake --build "$dir" -j "$jobs" 2>&1 | grep -Ev '^\[ *[0-9]+%\]|^-- ' || true
  [ "${PIPESTATUS[0]}" -eq 0 ] || { echo "Error   : build failed in $dir"; exit 1; }
}

case "$mode" in
  build)
    build build ;;
  demo)
    build build
    bash examples/demo.sh build ;;
  test)
    # Tests run side by side on few cores: OpenMP threads must not spin.
    export OMP_WAIT_POLICY=passive
    # getme-mpi's tests (label mpi) run mpirun as root in CI containers.
    export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
    build build -DGETME_WERROR=ON
    echo "Info    : running the test suite (release build)"
    ctest --test-dir build --output-on-failure -j "$jobs"
    build build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGETME_SANITIZE=ON -DGETME_WERROR=ON
    echo "Info    : running the test suite under AddressSanitizer + UndefinedBehaviorSanitizer"
    # Python-hosted tests load our library into /usr/bin/python3, which is not
    # built with ASan: they run in the release build only (label python).
    ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
      ctest --test-dir build-asan --output-on-failure -j "$jobs" -LE 'python|nosan'
    build build-core -DGETME_WERROR=ON -DGETME_WITH_GMSH=OFF \
      -DGETME_WITH_CGNS=OFF -DGETME_WITH_PYTHON=OFF
    echo "Info    : running the test suite of the core-only build (no Gmsh, CGNS, Python)"
    ctest --test-dir build-core --output-on-failure -j "$jobs"
    ;;
  *)
    echo "usage: bash scripts/setup.sh demo|test|build" >&2; exit 2 ;;
esac
