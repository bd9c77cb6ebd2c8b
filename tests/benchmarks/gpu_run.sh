#!/usr/bin/env bash
# The GPU figures of docs/results.md ("On an NVIDIA GPU"): run on a machine with the GPU, from a
# checkout, after preparing on the build machine (paths relative to the checkout, all ignored):
#   .whl/       the self-contained wheel for that machine's Python (.ci/build-wheel, run with it)
#   .benchdev/  ambfplus_bench*.so from build/cmake/benchmarks (the capture benchmark's C++
#               baseline), fixtures/volumetric_drilling (the original system's files, for the
#               stereo benchmark), and optionally h5site/ (hdf5plugin, where pip cannot fetch it)
#   .gl/        optionally the glvnd dispatch packages (libegl1, libopengl0, ...) as .deb files,
#               where the machine has the NVIDIA driver but not the dispatch libraries
# Installs the wheel, prints the GPU and what `ambfplus doctor` finds, then the capture, stereo,
# antialiasing and datasets benchmarks (each under a time limit, about 8 minutes in all). Files
# land in $OUT when it is set.
set -u -o pipefail
REPO=$(pwd)
OUT=${OUT:-$REPO/gpu-results}
mkdir -p "$OUT"
if compgen -G ".gl/*.deb" >/dev/null; then
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
nv=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
if [ -f "$nv" ] && ! ls /usr/share/glvnd/egl_vendor.d/*nvidia* >/dev/null 2>&1; then
  export __EGL_VENDOR_LIBRARY_FILENAMES=$nv
fi
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee "$OUT/gpu.txt"
python3 -m pip install -q --no-index --no-deps --no-compile .whl/ambfplus-*.whl
export PYTHONPATH=$REPO/.benchdev/h5site AMBFPLUS_BENCH_DIR=$REPO/.benchdev \
  AMBFPLUS_FIXTURES=$REPO/.benchdev/fixtures PYTHONUNBUFFERED=1
cd /tmp
timeout 60 python3 -m ambfplus doctor 2>&1 | tee "$OUT/doctor.txt"
for spec in "capture 60" "stereo 90" "antialiasing 45" "datasets 270"; do
  set -- $spec
  echo "== $1"
  timeout "$2" python3 "$REPO/tests/benchmarks/run.py" --only "$1" | tee "$OUT/$1.jsonl"
  echo "== $1: exit status $?"
done
