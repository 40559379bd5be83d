#!/usr/bin/env bash
# Soak run (the reliability issue's benchmark): the offline runner on a sequence played forward
# and backward for a long time, memory (RSS) and CPU sampled from /proc every few seconds.
#
#   bench/soak.sh [--bin DIR] [--out DIR] [--minutes M] [--mode mapping|localization|both] [--seed S]
#
# The sequence is walking_xyz (two people, the real fr3_walking_xyz camera path) generated once;
# OUT/pingpong lists its frames forward, backward, forward... with stamps continuing at 30 Hz, so
# the camera keeps revisiting the same room. mapping: SLAM as usual (keyframes may still be added
# on revisits; culling removes redundant ones). localization: the map of one forward pass is saved
# and loaded, and the run tracks in it without adding keyframes (memory must stay flat). Each run
# is stopped with SIGINT after M minutes (the runner then writes its results, exit code 130).
# Writes OUT/<mode>/rss.tsv (seconds, RSS MB, CPU % of one core over the last interval) and
# OUT/summary.json: RSS at 5 minutes and at the end, slope over the run's second half
# (MB per 10 minutes), mean CPU, frames processed, keyframes and map points at the end.
set -euo pipefail
bin=build/ws/devel/lib/yolo_slam
out=out/soak
minutes=30
mode=both
seed=1
interval=10
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --minutes) minutes="$2"; shift 2 ;;
    --mode) mode="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) echo "error: unknown option '$1'; see --help" >&2; exit 1 ;;
  esac
done
case "$mode" in mapping|localization|both) ;; *) echo "error: --mode must be mapping, localization or both" >&2; exit 1 ;; esac
for t in yolo_slam_synth yolo_slam_run; do
  [ -x "$bin/$t" ] || { echo "error: $bin/$t not found; build it (scripts/build.sh) or pass --bin DIR" >&2; exit 1; }
done
mkdir -p "$out"
echo "soak: $(date -u +%FT%TZ), load $(cut -d' ' -f1-3 /proc/loadavg), $minutes min per mode"
seq="$out/seq"
[ -f "$seq/associations.txt" ] || "$bin/yolo_slam_synth" --preset walking_xyz --seed "$seed" --out "$seq" > /dev/null

# The ping-pong folder: the same images, stamps rewritten. Enough passes for 60 frames/s.
pp="$out/pingpong"
/usr/bin/python3 - "$seq" "$pp" "$minutes" <<'PY'
import os, sys
seq, pp, minutes = sys.argv[1], sys.argv[2], float(sys.argv[3])
os.makedirs(pp, exist_ok=True)
for d in ("rgb", "depth"):
    link = os.path.join(pp, d)
    if not os.path.lexists(link):
        os.symlink(os.path.abspath(os.path.join(seq, d)), link)
rows = [l.split() for l in open(os.path.join(seq, "associations.txt")) if l.strip() and not l.startswith("#")]
gt = {}
for l in open(os.path.join(seq, "groundtruth.txt")):
    if l.strip() and not l.startswith("#"):
        f = l.split(); gt[f[0]] = f[1:]
order, n, passes = [], len(rows), 0
need = int(minutes * 60 * 60) + n
while len(order) < need:
    order += list(range(n)) if passes % 2 == 0 else list(range(n - 1, -1, -1))
    passes += 1
t0 = float(rows[0][0])
with open(os.path.join(pp, "rgb.txt"), "w") as rgb, open(os.path.join(pp, "depth.txt"), "w") as dep, \
     open(os.path.join(pp, "associations.txt"), "w") as asc, open(os.path.join(pp, "groundtruth.txt"), "w") as g:
    for k, i in enumerate(order):
        r = rows[i]
        t = "%.6f" % (t0 + k / 30.0)
        rgb.write(f"{t} {r[1]}\n"); dep.write(f"{t} {r[3]}\n"); asc.write(f"{t} {r[1]} {t} {r[3]}\n")
        if r[0] in gt:
            g.write(t + " " + " ".join(gt[r[0]]) + "\n")
import shutil
shutil.copy(os.path.join(seq, "camera.yaml"), os.path.join(pp, "camera.yaml"))
PY

# Samples RSS and CPU of PID into FILE every $interval s until it exits.
sample() {
  local pid=$1 file=$2 start ticks_prev=0 hz
  hz=$(getconf CLK_TCK)
  start=$(date +%s)
  printf "seconds\trss_mb\tcpu_percent\n" > "$file"
  while kill -0 "$pid" 2>/dev/null; do
    local rss ticks now
    rss=$(awk '/^VmRSS/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
    ticks=$(awk '{print $14 + $15}' "/proc/$pid/stat" 2>/dev/null || true)
    [ -n "$rss" ] && [ -n "$ticks" ] || break
    now=$(( $(date +%s) - start ))
    awk -v t="$now" -v r="$rss" -v d="$((ticks - ticks_prev))" -v hz="$hz" -v iv="$interval" \
      'BEGIN { printf "%d\t%.1f\t%.0f\n", t, r / 1024, 100 * d / hz / iv }' >> "$file"
    ticks_prev=$ticks
    sleep "$interval"
  done
}

# Runs the runner with ARGS for $minutes, then SIGINT; waits for its results.
soak_run() {
  local name=$1; shift
  mkdir -p "$out/$name"
  nice -n 19 "$bin/yolo_slam_run" --sequence "$pp" --out "$out/$name/run" "$@" > "$out/$name/run.log" 2>&1 &
  local pid=$!
  sample "$pid" "$out/$name/rss.tsv" &
  local sampler=$!
  local waited=0
  while kill -0 "$pid" 2>/dev/null && [ "$waited" -lt $((minutes * 60)) ]; do sleep 5; waited=$((waited + 5)); done
  kill -INT "$pid" 2>/dev/null || true
  wait "$pid" || true
  wait "$sampler" || true
  echo "soak: $name done at $(date -u +%TZ), load $(cut -d' ' -f1-3 /proc/loadavg)"
}

if [ "$mode" != localization ]; then soak_run mapping; fi
if [ "$mode" != mapping ]; then
  [ -f "$out/room.ysmap" ] || "$bin/yolo_slam_run" --sequence "$seq" --out "$out/map_run" --save-map "$out/room.ysmap" \
    > "$out/map_run.log" 2>&1
  soak_run localization --load-map "$out/room.ysmap" --localization
fi

/usr/bin/python3 - "$out" <<'PY'
import json, os, sys
out = sys.argv[1]
summary = {}
for name in ("mapping", "localization"):
    tsv = os.path.join(out, name, "rss.tsv")
    if not os.path.exists(tsv):
        continue
    rows = [tuple(map(float, l.split())) for l in list(open(tsv))[1:] if l.strip()]
    if len(rows) < 4:
        continue
    half = [r for r in rows if r[0] >= rows[-1][0] / 2]
    n = len(half)
    mt = sum(r[0] for r in half) / n
    mr = sum(r[1] for r in half) / n
    var = sum((r[0] - mt) ** 2 for r in half)
    slope = sum((r[0] - mt) * (r[1] - mr) for r in half) / var if var > 0 else 0.0
    at5 = min(rows, key=lambda r: abs(r[0] - 300))
    s = {"seconds": rows[-1][0], "rss_mb_at_5min": at5[1], "rss_mb_end": rows[-1][1],
         "rss_mb_max": max(r[1] for r in rows), "rss_slope_mb_per_10min_second_half": slope * 600,
         "cpu_percent_mean": sum(r[2] for r in rows[1:]) / max(1, len(rows) - 1)}
    stats_path = os.path.join(out, name, "run", "stats.json")
    if os.path.exists(stats_path):
        st = json.load(open(stats_path))
        for k in ("frames", "tracked", "lost", "keyframes", "keyframes_culled", "map_points", "loops_closed",
                  "relocalizations", "ate_rmse_m", "fps"):
            s[k] = st.get(k)
    summary[name] = s
json.dump(summary, open(os.path.join(out, "summary.json"), "w"), indent=2)
print(json.dumps(summary, indent=2))
PY
