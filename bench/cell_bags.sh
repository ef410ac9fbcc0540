#!/usr/bin/env bash
# H2's scaling run from recordings (docs/BENCHMARKS.md, "Cells with several cameras"): four
# cameras at 424x240 and 90 frames/s, each played from its own depth-only .bag, paced, into one
# fuser on this host. First it records the bags from the simulated 3-camera cell with a fourth
# camera added (`right`, opposite `left`), then it runs the fuser and the four camera processes
# by hand, each under /usr/bin/time, so that every process's CPU is its own.
#
#   bench/cell_bags.sh [BUILD_DIR] [FRAMES]       (default build/release, 1350 frames = 15 s)
#
# Outputs in out/bench-cell/: the bags, cell.yaml, fused.jsonl, NAME.jsonl and *.time (CPU).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/release}
frames=${2:-1350}
hrcsense="$build/hrcsense"
out=out/bench-cell
mkdir -p "$out"
export CYCLONEDDS_URI=${CYCLONEDDS_URI:-file://$PWD/tests/dds/cyclonedds-loopback.xml}

# The cell: config/cell-ur5-3cam.yaml at 424x240, 90 frames/s, depth only, plus `right`.
cameras='cameras:
  - {name: front, T_base_camera: {translation_m: [2.0, 0, 1.6], rotation_rpy_deg: [-133.3, 0, 90]}, fps: 90, source: {seed: 1}}
  - {name: left, T_base_camera: {translation_m: [0.3, 2.2, 1.5], rotation_rpy_deg: [-124.3, 0, 180]}, fps: 90, source: {seed: 2}}
  - {name: overhead_back, T_base_camera: {translation_m: [-1.3, 0.9, 2.4], rotation_rpy_deg: [-142.6, 0, -119.4]}, fps: 90, source: {seed: 3}}
  - {name: right, T_base_camera: {translation_m: [0.3, -2.2, 1.5], rotation_rpy_deg: [-124.3, 0, 0]}, fps: 90, source: {seed: 4}}'
names=(front left overhead_back right)
awk -v cams="$cameras" '
  /^cameras:/ { print cams; skip = 1; next }
  skip && /^  / { next }
  { skip = 0 }
  /^sim:/ { print "sim: {sensor: d435, width: 424, height: 240, fps: 90, frames: '"$frames"', noise: true, disparity_noise_px: 0.08, color: false}"; next }
  { print }' config/cell-ur5-3cam.yaml > "$out/sim.yaml"

for name in "${names[@]}"; do
  [[ -s "$out/$name.bag" ]] || "$hrcsense" record --config "$out/sim.yaml" --camera "$name" --out "$out/$name.bag" --overwrite
done

# The same cell played from the bags: each camera's source is its recording, its robot state
# the joint states recorded beside the frames.
bag_cameras=$(for name in "${names[@]}"; do
  printf '%s\n' "$cameras" | grep "name: $name," | sed "s|source: {seed: [0-9]*}|source: {type: bag, path: $out/$name.bag, pace: true}|"
done)
awk -v cams="cameras:
$bag_cameras" '
  /^cameras:/ { print cams; skip = 1; next }
  skip && /^  / { next }
  { skip = 0 }
  /^source:/ { print "source: {type: bag, path: '"$out"'/front.bag, pace: true}"; next }
  /^sim:/ { next }
  { print }' "$out/sim.yaml" > "$out/cell.yaml"

timed() { local name=$1; shift; /usr/bin/time -f "%U %S %e" -o "$out/$name.time" "$@"; }
recorded=(--set robot.state.source=recorded)
timed fuser "$hrcsense" fuse --config "$out/cell.yaml" "${recorded[@]}" --out "$out/fused.jsonl" 2> "$out/fuser.log" &
fuser_pid=$!
sleep 1  # the fuser's reader first, so that it sees every camera's first measurement
pids=()
for name in "${names[@]}"; do
  timed "$name" "$hrcsense" run --config "$out/cell.yaml" "${recorded[@]}" --camera "$name" --out "$out/$name.jsonl" 2> "$out/$name.log" &
  pids+=($!)
done
wait "${pids[@]}"
wait "$fuser_pid"

echo "process        user_s  system_s  wall_s  cpu_of_a_core"
for name in fuser "${names[@]}"; do
  read -r user system wall < "$out/$name.time"
  awk -v n="$name" -v u="$user" -v s="$system" -v w="$wall" \
    'BEGIN { printf "%-14s %6.2f %9.2f %7.2f %8.1f %%\n", n, u, s, w, 100 * (u + s) / w }'
done
echo "outputs: $out/fused.jsonl and $out/<camera>.jsonl (each summary: frames skipped, latency)"
