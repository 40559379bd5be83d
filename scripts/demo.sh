#!/usr/bin/env bash
# The README demo: installs dependencies, builds, generates a synthetic dynamic sequence
# (the walking_xyz analogue: two people walking, the real fr3_walking_xyz camera motion),
# runs YOLO-SLAM on it offline and evaluates the trajectory against the ground truth.
#   scripts/demo.sh [--preset NAME] [--frames N] [--mode off|detect|geometry|detect+geometry]
# Output: out/demo/<preset>/ (sequence) and out/demo/<preset>-run/ (trajectory, stats.json, plot).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"

preset=walking_xyz
frames=0
mode=detect+geometry
while [ $# -gt 0 ]; do
  case "$1" in
    --preset) preset="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --mode) mode="$2"; shift 2 ;;
    -h|--help) sed -n '2,7p' "$0"; exit 0 ;;
    *) echo "demo.sh: unknown argument $1 (see --help)"; exit 2 ;;
  esac
done

bash "$YS_ROOT/scripts/install_deps.sh"
# A fresh clone has no build/ (git-ignored): create it before logging into it.
mkdir -p "$YS_ROOT/build"
echo "== building (log: build/demo_build.log)"
bash "$YS_ROOT/scripts/build.sh" > "$YS_ROOT/build/demo_build.log" 2>&1 || {
  tail -30 "$YS_ROOT/build/demo_build.log"; echo "demo.sh: build failed (log: build/demo_build.log)"; exit 1; }

BIN="$YS_WS/devel/lib/yolo_slam"
seq="$YS_ROOT/out/demo/$preset"
run="$YS_ROOT/out/demo/$preset-run"
frames_arg=()
[ "$frames" != 0 ] && frames_arg=(--frames "$frames")

echo "== 1/3 generating the synthetic sequence '$preset' into $seq"
rm -rf "$seq"
mkdir -p "$(dirname "$seq")"
"$BIN/yolo_slam_synth" --preset "$preset" --seed 1 --out "$seq" "${frames_arg[@]}"

echo "== 2/3 running YOLO-SLAM (--dynamic-mode $mode)"
"$BIN/yolo_slam_run" --sequence "$seq" --config "$seq/camera.yaml" --out "$run" --dynamic-mode "$mode"

echo "== 3/3 evaluating against the ground truth"
"$BIN/yolo_slam_eval" ate "$seq/groundtruth.txt" "$run/CameraTrajectory.txt" --plot "$run/ate.png"
"$BIN/yolo_slam_eval" rpe "$seq/groundtruth.txt" "$run/CameraTrajectory.txt" --delta 1 --delta-unit s
echo "demo.sh: trajectory $run/CameraTrajectory.txt, statistics $run/stats.json, plot $run/ate.png"
