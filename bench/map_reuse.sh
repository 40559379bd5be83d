#!/usr/bin/env bash
# Map reuse (the map-file issue's benchmark): map the room without people along one camera path
# and save the map; load it in localization mode on another camera path of the same room with
# two people walking; evaluate the second run in the first map's frame (the mapping run's
# alignment onto the ground truth, not a new one).
#
#   bench/map_reuse.sh [--bin DIR] [--out DIR] [--frames N] [--seed S] [--loc-preset P]
#
# Mapping: preset static_xyz (camera translating along its axes, no people). Localization:
# preset P (default walking_xyz: the real fr3_walking_xyz camera path, two people; crowd and
# close have the same path). Both start at the same place in the seed's room. Prints frames
# tracked, when the first pose came (relocalisation), the map file's size and load time, and
# the ATE in the map's frame; writes OUT/summary.json.
set -euo pipefail
bin=build/ws/devel/lib/yolo_slam
out=out/map_reuse
frames=0
seed=1
loc_preset=walking_xyz
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --loc-preset) loc_preset="$2"; shift 2 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "error: unknown option '$1'; see --help" >&2; exit 1 ;;
  esac
done
for t in yolo_slam_synth yolo_slam_run yolo_slam_eval; do
  [ -x "$bin/$t" ] || { echo "error: $bin/$t not found; build it (scripts/build.sh) or pass --bin DIR" >&2; exit 1; }
done
mkdir -p "$out"
echo "map_reuse: $(date -u +%FT%TZ), load $(cut -d' ' -f1-3 /proc/loadavg)"
"$bin/yolo_slam_synth" --preset static_xyz --seed "$seed" --frames "$frames" --out "$out/map_seq" > /dev/null
"$bin/yolo_slam_synth" --preset "$loc_preset" --seed "$seed" --frames "$frames" --out "$out/loc_seq" > /dev/null
"$bin/yolo_slam_run" --sequence "$out/map_seq" --out "$out/map_run" --save-map "$out/room.ysmap" > "$out/map_run.log" 2>&1
"$bin/yolo_slam_run" --sequence "$out/loc_seq" --out "$out/loc_run" --load-map "$out/room.ysmap" --localization \
  > "$out/loc_run.log" 2>&1
"$bin/yolo_slam_eval" ate "$out/loc_seq/groundtruth.txt" "$out/loc_run/CameraTrajectory.txt" --json \
  --align-with "$out/map_seq/groundtruth.txt" "$out/map_run/CameraTrajectory.txt" > "$out/ate_in_map_frame.json"
"$bin/yolo_slam_eval" ate "$out/map_seq/groundtruth.txt" "$out/map_run/CameraTrajectory.txt" --json > "$out/ate_map_run.json"
/usr/bin/python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
def first_stamp(path):
    for line in open(path):
        if line.strip() and not line.startswith("#"):
            return float(line.split()[0])
    return None
loc = json.load(open(f"{out}/loc_run/stats.json"))
mapping = json.load(open(f"{out}/map_run/stats.json"))
ate = json.load(open(f"{out}/ate_in_map_frame.json"))
ate_map = json.load(open(f"{out}/ate_map_run.json"))
t0 = first_stamp(f"{out}/loc_seq/groundtruth.txt")
t1 = first_stamp(f"{out}/loc_run/CameraTrajectory.txt")
saved = mapping["map_file"]["saved"]
loaded = loc["map_file"]["loaded"]
s = {"map": {"keyframes": saved["keyframes"], "map_points": saved["map_points"], "bytes": saved["bytes"],
             "save_ms": saved["ms"], "load_ms": loaded["ms"], "mapping_ate_m": ate_map["rmse"]},
     "localization": {"frames": loc["frames"], "tracked": loc["tracked"],
                      "tracked_fraction": loc["tracked"] / max(1, loc["frames"]),
                      "first_pose_after_s": None if t1 is None else t1 - t0,
                      "keyframes_added": loc["keyframes"] - saved["keyframes"],
                      "ate_in_map_frame_m": ate["rmse"], "pairs": ate["pairs"]}}
json.dump(s, open(f"{out}/summary.json", "w"), indent=1)
m, l = s["map"], s["localization"]
print(f"map: {m['keyframes']} keyframes, {m['map_points']} points, {m['bytes'] / 1e6:.2f} MB, save {m['save_ms']:.0f} ms, "
      f"load {m['load_ms']:.0f} ms; mapping run ATE {m['mapping_ate_m']:.4f} m")
print(f"localization: {l['tracked']}/{l['frames']} frames tracked ({100 * l['tracked_fraction']:.1f} %), first pose "
      f"{l['first_pose_after_s']:.3f} s after the first frame, {l['keyframes_added']} keyframes added, "
      f"ATE in the map's frame {l['ate_in_map_frame_m']:.4f} m over {l['pairs']} poses")
PY
echo "map_reuse: done $(date -u +%FT%TZ), load $(cut -d' ' -f1-3 /proc/loadavg); $out/summary.json"
