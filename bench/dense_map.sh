#!/usr/bin/env bash
# Dense static map benchmark (issue 20): on a generated walking preset, the static mask against
# the generated masks, and the dense map (yolo_slam_run --octomap --cloud) against the scene's
# geometry with screening and with screening off; the tracking thread's time per frame with
# and without the dense map; memory. Writes OUT/table.md and one JSON per measurement.
#
#   bench/dense_map.sh [--bin DIR] [--preset NAME] [--frames N] [--seed S] [--out DIR]
#                      [--detector] [--step N]
#
# Person boxes come from the sequence's ground truth (--boxes-from-gt) so the map is scored
# apart from detection misses; --detector adds a run with the detector (Detector.model).
# Runs are threaded (the default System), one at a time, under nice -n 10; `uptime` is logged
# before each run because the machine may be shared.
set -eu

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/.." && pwd)"
bin="$repo/build-core"
preset=walking_xyz
frames=300
seed=1
out="$repo/out/dense_map"
detector=0
step=5
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --preset) preset="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --detector) detector=1; shift ;;
    --step) step="$2"; shift 2 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "error: unknown option '$1'; see --help" >&2; exit 1 ;;
  esac
done
for tool in yolo_slam_synth yolo_slam_run dense_map_bench slam_bench; do
  [ -x "$bin/$tool" ] || { echo "error: $bin/$tool not found; build it or pass --bin DIR" >&2; exit 1; }
done

mkdir -p "$out"
seq="$out/seq/${preset}_f${frames}_s${seed}"
if [ ! -f "$seq/associations.txt" ]; then
  mkdir -p "$out/seq"
  nice -n 10 "$bin/yolo_slam_synth" --preset "$preset" --seed "$seed" --frames "$frames" --out "$seq"
fi

echo "static mask vs masks/ (every ${step}th frame)"
for mode in detect+geometry detect; do
  nice -n 10 "$bin/dense_map_bench" mask --sequence "$seq" --step "$step" --set "Screening.mode=$mode" \
    > "$out/mask_${mode}.json"
done

# run NAME [yolo_slam_run options...]
run() {
  local name="$1"; shift
  local dir="$out/run_$name"
  mkdir -p "$dir"
  echo "run $name: $(uptime)" | tee "$dir/uptime.txt"
  /usr/bin/time -v nice -n 10 "$bin/yolo_slam_run" --sequence "$seq" --out "$dir" "$@" \
    > "$dir/log.txt" 2> "$dir/stderr.txt"
  grep "Maximum resident" "$dir/stderr.txt" | awk '{print $NF}' > "$dir/max_rss_kb.txt"
}
score() {
  local name="$1"
  nice -n 10 "$bin/dense_map_bench" score --sequence "$seq" --trajectory "$out/run_$name/CameraTrajectory.txt" \
    --octomap "$out/run_$name/map.bt" --step "$step" > "$out/score_$name.json"
}

dense_run() {
  local name="$1"; shift
  mkdir -p "$out/run_$name"
  run "$name" --octomap "$out/run_$name/map.bt" --cloud "$out/run_$name/cloud.ply" "$@"
  score "$name"
}
dense_run screening --boxes-from-gt
# Tracking screened as above, but every pixel integrated: the ghosts of a plain fusion.
dense_run plain --boxes-from-gt --set DenseMap.maskPeople=0
# Screening off altogether (tracking too).
dense_run off --boxes-from-gt --dynamic-mode off
if [ "$detector" = 1 ]; then dense_run detector; fi

# Tracking-thread time per frame (slam_bench: wall and CPU of System::trackRgbd in the caller's
# thread; ground-truth boxes, no detector, no vocabulary) without and with the dense map, interleaved twice so a
# change of the machine's load hits both alike.
for k in 1 2; do
  for dense in 0 1; do
    echo "slam_bench dense=$dense ($k): $(uptime)" | tee -a "$out/timing_uptime.txt"
    nice -n 10 "$bin/slam_bench" --sequence "$seq" --config "$seq/camera.yaml" --dynamic-mode detect+geometry --boxes-from-gt \
      --set "DenseMap.enabled=$dense" > "$out/timing_dense${dense}_$k.txt"
  done
done

/usr/bin/python3 - "$out" "$preset" "$frames" <<'PY'
import json, os, sys
out, preset, frames = sys.argv[1], sys.argv[2], sys.argv[3]
def load(name):
    p = os.path.join(out, name)
    return json.load(open(p)) if os.path.exists(p) else None
def pct(x):
    return "-" if x is None else f"{100 * x:.2f} %"
rows = ["| run | occupied voxels | on people | off static surfaces | static coverage (2 voxels) | cloud points | keyframes | integration ms (wall / CPU, median) | rebuild ms | dense map MB | max RSS MB |",
        "|---|---|---|---|---|---|---|---|---|---|---|"]
for name in ("screening", "plain", "off", "detector"):
    s, st = load(f"score_{name}.json"), load(f"run_{name}/stats.json")
    if not s or not st:
        continue
    d = st["dense_map"]
    rss = open(os.path.join(out, f"run_{name}", "max_rss_kb.txt")).read().strip()
    rows.append(f"| {name} | {s['occupied_voxels']} | {pct(s['on_people_share'])} | {pct(s['off_static_share'])} | "
                f"{pct(s['static_coverage'])} | {d['points']} | {d['keyframes']} | "
                f"{d['integration_ms']['median_ms']:.0f} / {d['integration_cpu_ms']['median_ms']:.0f} | "
                f"{d['rebuild_ms']['median_ms']:.0f} | {d['memory_mb']:.1f} | {int(rss) / 1024:.0f} |")
mask = ["| static mask | person pixels left static | static pixels removed |", "|---|---|---|"]
for mode in ("detect+geometry", "detect"):
    m = load(f"mask_{mode}.json")
    if m:
        mask.append(f"| {mode} (margin {m['mask_margin_px']} px) | {pct(m['person_left_static_share'])} | {pct(m['static_removed_share'])} |")
import re, statistics
def bench_medians(dense):
    wall, cpu = [], []
    for k in (1, 2):
        p = os.path.join(out, f"timing_dense{dense}_{k}.txt")
        if not os.path.exists(p):
            continue
        txt = open(p).read()
        wall.append(float(re.search(r"tracking wall: median ([0-9.]+)", txt).group(1)))
        cpu.append(float(re.search(r"tracking cpu:  median ([0-9.]+)", txt).group(1)))
    return (statistics.median(wall), statistics.median(cpu)) if wall else None
t = []
a, b = bench_medians(1), bench_medians(0)
if a and b:
    t = ["| tracking thread per frame (slam_bench, median of 2 runs' medians) | with dense map | without | ratio |",
         "|---|---|---|---|",
         f"| wall | {a[0]:.1f} ms | {b[0]:.1f} ms | {a[0] / b[0]:.3f} |",
         f"| CPU | {a[1]:.1f} ms | {b[1]:.1f} ms | {a[1] / b[1]:.3f} |", "",
         "```", open(os.path.join(out, "timing_uptime.txt")).read().strip(), "```"]
text = f"# Dense map on {preset}, {frames} frames\n\n" + "\n".join(mask) + "\n\n" + "\n".join(rows) + "\n\n" + "\n".join(t) + "\n"
open(os.path.join(out, "table.md"), "w").write(text)
print(text)
PY
