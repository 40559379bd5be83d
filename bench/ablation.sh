#!/usr/bin/env bash
# Ablation benchmark of the dynamic-feature modes (issue 7, item 5): the paper's Table 3
# (ORB-SLAM2 / D / G / D+G) on the synthetic TUM-analogue presets, plus RPE, tracking and time.
#
#   bench/ablation.sh [--bin DIR] [--frames N] [--runs R] [--presets "a b c"] [--modes "..."]
#                     [--out DIR] [--seed S] [--timeout SEC] [--realtime] [--table-only]
#
# --realtime paces the frames at the sequence's 30 Hz as a camera (or ORB-SLAM2's rgbd_tum
# example) does; without it frames are fed as fast as the system takes them, and the modes
# that run the detector leave local mapping less CPU per frame than mode off.
#
# A mode may carry suffixes, each starting with ':' (e.g. "detect+geometry:gt:noveto"):
#   :gt       person boxes from the sequence's ground-truth boxes.txt instead of the detector
#             (separates detection misses from screening/tracking errors)
#   :notrack  no box tracking between detections (--track-boxes off)
#   :veto / :noveto   static-box veto on / off (--static-box-veto)
#   :prop / :noprop   label propagation on / off (--propagate-labels)
#   :motion / :nomotion   motion screening on / off (--set Screening.motionScreening=1/0)
#   :nobeyond no screening beyond the boxes (--set Screening.noDepthHoleRadius=0 and
#             Screening.growOutside=0: the person mask, its growth and the hole rule off)
#   :single   the main detection model alone, without Detector.extraModels (--single-model)
#   :every / :async   detection on every frame before it is screened (the paper's pipeline,
#             the default of yolo_slam_run) / asynchronous detection (the ROS launch files' default)
#   :seq      the deterministic mode (--sequential): one run is all runs
#   :orbkf    ORB-SLAM2's keyframe rules (Tracking.closeMinFrames=0, Tracking.keyFramePoints=100)
#   :noyoung  no young-point check (--set Tracking.youngPointCheck=0): "off:orbkf:noyoung" is
#             the nearest to ORB-SLAM2; plain "off" is this SLAM without screening
#   :camera   frames fed at 30 Hz as a live camera, dropped while busy (--camera-rate)
# ":notrack:noveto:noprop:single" is the paper's method as printed.
# Each preset is generated once (fixed seed; reused when the same preset/frames/seed exists in
# OUT/seq), each mode runs R times (the system is multi-threaded, runs differ), each run is
# evaluated with yolo_slam_eval (ATE, RPE delta 1 s); bench/ablation_table.py takes the medians
# and writes OUT/table.md. A failed run is logged and shown as failed in the table; the script
# carries on. OUT/meta.txt records the command, commit, load and the machine's speed before and
# after (features_bench's ORB extraction median: read frame rates of two tables against it).
set -u

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/.." && pwd)"
bin="$repo/build/ws/devel/lib/yolo_slam"
frames=0
runs=3
presets="walking_xyz walking_static walking_rpy walking_half sitting_static static_xyz"
modes="off detect geometry detect+geometry"
out="$repo/out/ablation"
seed=1
timeout_s=3600
table_only=0
pace=()

usage() {
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}"
  echo "defaults: --bin build/ws/devel/lib/yolo_slam --frames 0 (preset length) --runs 3 --seed 1"
  echo "          --presets \"$presets\""
  echo "          --modes \"$modes\" --out out/ablation --timeout 3600 (per run, seconds)"
}

need() { [ $# -ge 2 ] && [ -n "$2" ] || { echo "error: $1 needs a value; see --help" >&2; exit 1; }; }
posint() { [[ "$2" =~ ^[0-9]+$ ]] && [ "$2" -ge "$3" ] || { echo "error: $1 must be an integer >= $3 (got '$2')" >&2; exit 1; }; }

while [ $# -gt 0 ]; do
  case "$1" in
    --bin) need "$@"; bin="$2"; shift 2 ;;
    --frames) need "$@"; posint "$1" "$2" 0; frames="$2"; shift 2 ;;
    --runs) need "$@"; posint "$1" "$2" 1; runs="$2"; shift 2 ;;
    --presets) need "$@"; presets="$2"; shift 2 ;;
    --modes) need "$@"; modes="$2"; shift 2 ;;
    --out) need "$@"; out="$2"; shift 2 ;;
    --seed) need "$@"; posint "$1" "$2" 0; seed="$2"; shift 2 ;;
    --timeout) need "$@"; posint "$1" "$2" 1; timeout_s="$2"; shift 2 ;;
    --realtime) pace=(--realtime); shift ;;
    --table-only) table_only=1; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "error: unknown option '$1'; see --help" >&2; exit 1 ;;
  esac
done

# Runner options for a mode's suffixes (in the array `extra`); returns 1 on an unknown suffix.
suffix_options() {
  extra=()
  local rest="${1#"${1%%:*}"}" s
  local -a parts
  IFS=':' read -r -a parts <<< "$rest"
  for s in "${parts[@]}"; do
    case "$s" in
      "") ;;
      gt) extra+=(--boxes-from-gt) ;;
      notrack) extra+=(--track-boxes off) ;;
      veto) extra+=(--static-box-veto on) ;;
      noveto) extra+=(--static-box-veto off) ;;
      prop) extra+=(--propagate-labels on) ;;
      noprop) extra+=(--propagate-labels off) ;;
      motion) extra+=(--set Screening.motionScreening=1) ;;
      nomotion) extra+=(--set Screening.motionScreening=0) ;;
      nobeyond) extra+=(--set Screening.noDepthHoleRadius=0 --set Screening.growOutside=0) ;;
      single) extra+=(--single-model) ;;
      every) extra+=(--detection every-frame) ;;
      async) extra+=(--detection async) ;;
      seq) extra+=(--sequential) ;;
      orbkf) extra+=(--set Tracking.closeMinFrames=0 --set Tracking.keyFramePoints=100) ;;
      noyoung) extra+=(--set Tracking.youngPointCheck=0) ;;
      camera) extra+=(--camera-rate) ;;
      *) return 1 ;;
    esac
  done
}

for m in $modes; do
  case "${m%%:*}" in
    off|detect|geometry|detect+geometry) ;;
    *) echo "error: unknown mode '$m' in --modes; use off, detect, geometry, detect+geometry" >&2; exit 1 ;;
  esac
  suffix_options "$m" || { echo "error: unknown suffix in mode '$m'; use :gt :notrack :veto :noveto :prop :noprop :motion :nomotion :nobeyond :single :every :async :seq :orbkf :noyoung :camera" >&2; exit 1; }
done
py=/usr/bin/python3
[ -x "$py" ] || py=python3
if [ "$table_only" = 0 ]; then
  for t in yolo_slam_synth yolo_slam_run yolo_slam_eval; do
    [ -x "$bin/$t" ] || { echo "error: $bin/$t not found; build it (scripts/build.sh) or pass --bin DIR" >&2; exit 1; }
  done
fi
mkdir -p "$out" || { echo "error: cannot create $out" >&2; exit 1; }
out="$(cd "$out" && pwd)"

log() { echo "[$(date +%H:%M:%S)] $*"; }

# The machine's speed: this VM's single-thread speed has varied 2.3x within an hour (ORB
# extraction of one real frame 4.1-9.7 ms), so a frame rate means something only next to it.
gauge() {
  if [ -x "$bin/features_bench" ]; then
    "$bin/features_bench" 2>/dev/null | awk '/^extract/ {print "ORB extraction of the shared TUM frame, median " $3 " ms (features_bench)"; f=1} END {if (!f) print "features_bench failed"}'
  else
    echo "n/a ($bin/features_bench not built)"
  fi
}

# Everything needed to reproduce the table, read back by ablation_table.py.
{
  echo "command: bench/ablation.sh --frames $frames --runs $runs --presets \"$presets\" --modes \"$modes\" --seed $seed${pace[*]:+ ${pace[*]}}"
  echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "commit: $(git -C "$repo" rev-parse --short HEAD 2>/dev/null || echo unknown)$(git -C "$repo" diff --quiet HEAD -- src include tools 2>/dev/null || echo ' (+uncommitted changes in src/include/tools)')"
  echo "bin: $bin (yolo_slam_run built $(date -u -r "$bin/yolo_slam_run" +%Y-%m-%dT%H:%M:%SZ 2>/dev/null || echo '?'))"
  echo "load_before: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null)"
  [ "$table_only" = 0 ] && echo "gauge_before: $(gauge)"
  echo "cpus: $(nproc 2>/dev/null)"
} > "$out/meta.txt.new"
# Several invocations may fill one OUT (e.g. a second one adding ":gt" modes): keep every block.
if [ "$table_only" = 1 ]; then rm -f "$out/meta.txt.new"; else cat "$out/meta.txt.new" >> "$out/meta.txt"; rm -f "$out/meta.txt.new"; fi

if [ "$table_only" = 0 ]; then
  for preset in $presets; do
    seq="$out/seq/$preset"
    want="preset=$preset frames=$frames seed=$seed"
    if [ -f "$seq/.ablation_stamp" ] && [ "$(cat "$seq/.ablation_stamp")" = "$want" ]; then
      log "$preset: reusing $seq"
    else
      log "$preset: generating ($want)"
      rm -rf "$seq"
      mkdir -p "$seq"
      if "$bin/yolo_slam_synth" --preset "$preset" --frames "$frames" --seed "$seed" --threads 1 --out "$seq" \
          > "$out/seq/$preset.log" 2>&1; then
        echo "$want" > "$seq/.ablation_stamp"
      else
        log "$preset: generation FAILED (see $out/seq/$preset.log)"
        continue
      fi
    fi
    for mode in $modes; do
      base="${mode%%:*}"
      suffix_options "$mode"
      for r in $(seq 1 "$runs"); do
        dir="$out/runs/$preset/${mode//:/_}/run$r"
        rm -rf "$dir"
        mkdir -p "$dir"
        echo "$mode" > "$dir/mode.txt"
        t0=$(date +%s)
        timeout -s TERM -k 60 "$timeout_s" "$bin/yolo_slam_run" --sequence "$seq" --config "$seq/camera.yaml" \
          --out "$dir" --dynamic-mode "$base" "${extra[@]}" "${pace[@]}" > "$dir/run.log" 2>&1
        rc=$?
        echo "$rc" > "$dir/rc.txt"
        if [ "$rc" = 0 ] && [ -s "$dir/CameraTrajectory.txt" ]; then
          "$bin/yolo_slam_eval" ate "$seq/groundtruth.txt" "$dir/CameraTrajectory.txt" --json > "$dir/ate.json" 2> "$dir/eval.log" \
            || rm -f "$dir/ate.json"
          "$bin/yolo_slam_eval" rpe "$seq/groundtruth.txt" "$dir/CameraTrajectory.txt" --delta 1 --delta-unit s --json \
            > "$dir/rpe.json" 2>> "$dir/eval.log" || rm -f "$dir/rpe.json"
          ate=$(sed -n 's/.*"rmse": *\([-0-9.eE+]*\).*/\1/p' "$dir/ate.json" 2>/dev/null)
          log "$preset $mode run $r: rc 0, $(( $(date +%s) - t0 )) s, ATE ${ate:-n/a} m"
        else
          log "$preset $mode run $r: FAILED rc $rc after $(( $(date +%s) - t0 )) s ($(tail -c 300 "$dir/run.log" | tr '\r\n' '  ' | sed 's/.*error:/error:/'))"
        fi
      done
    done
  done
fi

[ "$table_only" = 0 ] && echo "finished: $(date -u +%Y-%m-%dT%H:%M:%SZ), load_after: $(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null), gauge_after: $(gauge)" >> "$out/meta.txt"
"$py" "$here/ablation_table.py" "$out" > "$out/table.md.new" && mv "$out/table.md.new" "$out/table.md" \
  || { echo "error: ablation_table.py failed on $out" >&2; exit 1; }
log "wrote $out/table.md"
