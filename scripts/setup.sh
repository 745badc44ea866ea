#!/usr/bin/env bash
# Installs exactly the Debian 12 packages augocc needs; skips what is already present.
# Idempotent. Runs apt-get as root; otherwise prints the command to run.
set -euo pipefail

PACKAGES=(
    build-essential cmake pkg-config
    libopencv-dev libopencv-contrib-dev   # OpenCV 4.6 core/imgproc/video/videoio/highgui + ximgproc
    libeigen3-dev                         # linear algebra for factorization and Ceres functors
    libceres-dev                          # Levenberg-Marquardt refinement and bundle adjustment
    libosmesa6-dev                        # headless OpenGL (Mesa llvmpipe) for synth and compositing
    libcli11-dev                          # sub-command parsing of the augocc CLI
    libassimp-dev                         # OBJ / PLY / glTF meshes for virtual objects
    libgtest-dev libgmock-dev googletest  # unit and accuracy tests
    libbenchmark-dev                      # perf suite
    python3                               # perf comparison and contact-sheet scripts (stdlib only)
    python3-dev pybind11-dev              # `import augocc`: the Python module (modules/augocc/python)
    python3-numpy python3-pytest          # its arrays and its tests (test/python, through CTest)
    python3-opencv                        # cv2 in those tests; augocc.error subclasses cv2.error
    xvfb xdotool                          # end-to-end test of the interactive annotate tool
    ffmpeg                                # ffprobe for video checks in tests; ffmpeg for synth --bitrate
    doxygen texlive-base                  # API docs and their test (bibtex for @cite)
    slurm-wlm munge                       # augocc farm's test: a single-node Slurm cluster
    shellcheck                            # the farm's generated job scripts are checked with it
    clang libclang-rt-14-dev              # libFuzzer + ASan/UBSan runtimes of the fuzz tree (fuzz/, scripts/fuzz.sh)
    blender                               # Blender 3.4: tests of augocc export-blender (blender -b; its UI under xvfb)
)

missing=()
for p in "${PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$p")
    fi
done

if [ ${#missing[@]} -eq 0 ]; then
    echo "setup: all ${#PACKAGES[@]} packages present"
    exit 0
fi

echo "setup: installing ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
    echo "setup: not root; run:  sudo apt-get update && sudo apt-get install -y ${missing[*]}" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
