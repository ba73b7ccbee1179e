#!/usr/bin/env bash
# Installs the Debian 12 packages sph needs to build, run and test, when they
# are missing. Usable as root or through sudo. Options:
#   --with-ffmpeg   also install ffmpeg (sph run then assembles an mp4)
#   --with-fuzz     also install clang with libFuzzer and the sanitizer
#                   runtimes, LLVM's OpenMP and symbolizer
#                   (tests/fuzz/run_fuzz.sh)
#   --with-cuda     also install Debian's nvidia-cuda-toolkit (nvcc, from the
#                   non-free component) unless an nvcc is already there (on
#                   PATH or /usr/local/cuda/bin): the GPU step (docs/gpu.md)
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libyaml-dev       # scene files (libyaml document API)
  libmatheval-dev   # expressions in scene files (velocity profiles)
  check             # unit test framework
  zlib1g-dev        # checkpoint checksums (CRC-32)
  libexpat1-dev     # the XML of .pvd/.vtp/.pvtp files read back (sph render)
  libpng-dev        # PNG frames
  libosmesa6-dev    # off-screen OpenGL renderer
  libfreetype-dev fonts-dejavu-core  # text on frames
  libfontconfig-dev # the frames' font found through fontconfig
  # ParaView as a tested client (io_paraview: pvbatch under xvfb-run); its
  # Python package's vtkmodules are VTK's own readers, which validate the
  # files we write (tests); it conflicts with python3-vtk9, which it replaces
  paraview python3-paraview xvfb xauth  # xvfb-run needs xauth (a Recommends)
  libassimp-dev     # bodies from mesh files: STL, OBJ, PLY... (optional: without it mesh scenes are refused)
  python3-numpy     # the sph Python package's field arrays (python/sph)
  python3-pytest    # the Python package's tests (tests/python)
  clang-format      # formatting is a test
  gnuplot-nox       # sph study figures (pngcairo)
  libopenmpi-dev openmpi-bin  # distributed runs (mpirun -np N sph run)
)
for arg in "$@"; do
  case "$arg" in
    --with-ffmpeg) packages+=(ffmpeg) ;;
    # clang-14's libFuzzer, ASan and UBSan runtimes are in libclang-rt-14-dev;
    # clang builds OpenMP code against libomp; llvm-14 has llvm-symbolizer
    --with-fuzz) packages+=(clang libclang-rt-14-dev libomp-14-dev llvm-14) ;;
    --with-cuda)
      if command -v nvcc >/dev/null || [ -x /usr/local/cuda/bin/nvcc ]; then
        echo "bootstrap: nvcc present, nvidia-cuda-toolkit not needed"
      else
        packages+=(nvidia-cuda-toolkit)
      fi ;;
    *) echo "bootstrap.sh: unknown option $arg" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "bootstrap: all ${#packages[@]} packages present"
  exit 0
fi

sudo=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "bootstrap: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo=(sudo)
fi
echo "bootstrap: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
