#!/usr/bin/env bash
# The one list of what microcobot needs on a Debian 12 machine.
# Idempotent: installs only what is missing and is silent when everything is present.
# Usage: scripts/install-deps.sh [run|test]   run: what `make run` needs; test (default): everything
#        (python3-scipy also regenerates the reference data of tests/data)
set -euo pipefail
cd "$(dirname "$0")/.."

# What `make run` needs: the toolchain and the libraries the `microcobot` program links.
RUN_PACKAGES=(
  build-essential cmake ninja-build pkg-config
  ccache               # compilations cached across build trees (CI rebuilds only what changed)
  lld                  # LLVM's linker: links three times faster than GNU ld (MC_LLD)
  libeigen3-dev        # linear algebra, matrix exponential, FFT, Levenberg-Marquardt
  libyaml-cpp-dev      # parameter files
  libcli11-dev         # command line
  libspdlog-dev libfmt-dev  # logging and formatting
  nlohmann-json3-dev   # --json output
  libboost-dev         # odeint (reference ODE solver); Beast/Asio (HTTP + WebSocket server)
  nodejs npm           # uPlot (bundled into reports and the console) and the test clients
  libmatio-dev         # MATLAB .mat files in and out (core/mat_file)
  libzstd-dev          # zstd-compressed chunks of the MCAP recordings (core/zstd)
  libturbojpeg0-dev    # the camera's JPEG frames (core/jpeg)
  libavcodec-dev       # the recordings' H.264 video: libavcodec with libx264 (live/h264_encoder)
  libpng-dev           # the camera's PNG frames (imaging/png_file; zlib comes with it)
  libopencv-imgproc-dev libopencv-video-dev  # vision processing: template matching, ECC (vision/template_tracker)
  cyclonedds-dev cyclonedds-tools  # the DDS link between master and slave processes (src/microcobot/net; idlc)
)
# What `make test` needs beside them: test frameworks, the browser, the fuzzers, the Python module
# and its independent references.
TEST_PACKAGES=(
  clang-format
  graphviz             # dot: the module graph of docs/architecture.md (make graph, checked by a test)
  iproute2             # ip netns: the two-machine link test runs each end in its own network stack
  libgtest-dev libgmock-dev googletest  # unit tests
  libbenchmark-dev     # benchmarks
  chromium             # headless browser for the report and console tests
  clang libclang-rt-14-dev  # libFuzzer harnesses of the parsers (scripts/fuzz.sh, make fuzz)
  pybind11-dev python3-dev python3-numpy  # the Python module (python/, `make python`)
  python3-scipy python3-pytest  # Python tests: scipy.signal / scipy.io as independent references
  libopencv-videoio-dev  # the real-camera driver (devices/opencv_camera.cc; CMake MC_WITH_OPENCV), built and tested by `make test`
  gstreamer1.0-plugins-base  # videotestsrc: the OpenCV driver's synthetic source in its test
  python3-pil          # an independent PNG reader for the camera's frames (tests/python/test_vision.py)
  ffmpeg               # an independent H.264 decoder for the recordings' video (tests/live/h264_encoder_test.cc, tests/mcap/recorded_video.mjs)
  python3-pymeasure python3-pyvisa-py  # independent clients of the GCS 2.0 / ANC300 twins
  python3-dask python3-distributed  # microcobot.cell.batch: campaigns of many seeds on a process pool or a cluster
  python3-pandas       # the tutorials' DataFrames (examples/platform_pandas.py, examples/cell_compare.py)
  mkdocs mkdocs-material  # the documentation site (make docs; docs/dependencies.md says why MkDocs)
  doxygen              # the C++ headers' reference in the site
)
DEBIAN_PACKAGES=("${RUN_PACKAGES[@]}")
[[ "${1:-test}" == run ]] || DEBIAN_PACKAGES+=("${TEST_PACKAGES[@]}")

missing=()
for p in "${DEBIAN_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing+=("$p")
done
# nodejs from another source may already provide npm: accept any working node+npm.
if command -v node >/dev/null && command -v npm >/dev/null; then
  tmp=(); for p in "${missing[@]}"; do [[ "$p" == nodejs || "$p" == npm ]] || tmp+=("$p"); done
  missing=("${tmp[@]+"${tmp[@]}"}")
fi
if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}" >&2
  SUDO=""; [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# npm packages pinned by package-lock.json (uPlot for reports and the console, playwright-core for
# the browser tests, @mcap/core for the MCAP tests with @foxglove/wasm-zstd to decompress the live
# recordings' chunks, @foxglove/ws-protocol for the protocol test).
if [[ ! -d node_modules/uplot || ! -d node_modules/playwright-core || ! -d node_modules/@mcap/core ||
      ! -d node_modules/@foxglove/ws-protocol || ! -d node_modules/@foxglove/wasm-zstd ||
      ! -d node_modules/@foxglove/rosmsg2-serialization ||
      package-lock.json -nt node_modules/.package-lock.json ]]; then
  echo "install-deps: npm ci" >&2
  npm ci --no-audit --no-fund --loglevel=error >/dev/null
fi
