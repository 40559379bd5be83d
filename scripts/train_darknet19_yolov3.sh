#!/usr/bin/env bash
# Train the paper's Darknet19-YOLOv3 (models/darknet19-yolov3.cfg) as a person detector with
# Debian's darknet binary (CPU) on PASCAL VOC-format data.
#
# usage: scripts/train_darknet19_yolov3.sh VOC_DIR [VOC_DIR...]
#   VOC_DIR: a VOC folder with Annotations/, JPEGImages/, ImageSets/Main/<SET>.txt
#            (e.g. VOCdevkit/VOC2007 and VOCdevkit/VOC2012, as in the paper)
# environment (defaults in brackets):
#   WORK          output folder [./darknet19-yolov3-train]
#   SET           VOC image set [trainval]
#   MAX_BATCHES   training iterations [10000, the paper's]
#   BATCH         images per iteration [64] ; SUBDIVISIONS [16] (the paper's)
#   PRETRAINED    optional initial weights (e.g. ImageNet Darknet-19 conv layers made with
#                 `darknet partial darknet19.cfg darknet19.weights darknet19.conv.23 23`)
#   DARKNET       darknet binary [/usr/bin/darknet, Debian package darknet]
# result: $WORK/model/{darknet19-yolov3.cfg,darknet19-yolov3.weights,person.names}, a model
# folder for `yolo_slam_detect --model $WORK/model` or Detector.model.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
cfg="$root/models/darknet19-yolov3.cfg"
WORK=${WORK:-./darknet19-yolov3-train}
SET=${SET:-trainval}
MAX_BATCHES=${MAX_BATCHES:-10000}
BATCH=${BATCH:-64}
SUBDIVISIONS=${SUBDIVISIONS:-16}
DARKNET=${DARKNET:-/usr/bin/darknet}
PRETRAINED=${PRETRAINED:-}

die() { echo "error: $*" >&2; exit 1; }
[ $# -ge 1 ] || die "usage: $0 VOC_DIR [VOC_DIR...] (see the header of $0)"
[ -x "$DARKNET" ] || die "darknet binary $DARKNET not found; apt-get install darknet or set DARKNET"
[ -f "$cfg" ] || die "$cfg not found; run from a yolo_slam checkout"
[ -z "$PRETRAINED" ] || [ -f "$PRETRAINED" ] || die "PRETRAINED=$PRETRAINED not found"
for n in MAX_BATCHES BATCH SUBDIVISIONS; do
  [[ ${!n} =~ ^[1-9][0-9]*$ ]] || die "$n must be a positive integer (got '${!n}')"
done
[ $((BATCH % SUBDIVISIONS)) -eq 0 ] || die "BATCH ($BATCH) must be a multiple of SUBDIVISIONS ($SUBDIVISIONS)"

mkdir -p "$WORK"
WORK=$(cd "$WORK" && pwd)
voc_args=()
for v in "$@"; do voc_args+=(--voc "$v"); done

# 1. VOC XML -> Darknet labels (person only).
/usr/bin/python3 "$here/train/voc_to_darknet.py" "${voc_args[@]}" --set "$SET" --classes person --out "$WORK/data"

# 2. Training copy of the cfg: training batch, iteration count, LR steps at 80% and 90%.
train_cfg="$WORK/darknet19-yolov3-train.cfg"
sed -e "s/^batch=.*/batch=$BATCH/" -e "s/^subdivisions=.*/subdivisions=$SUBDIVISIONS/" \
    -e "s/^max_batches *=.*/max_batches = $MAX_BATCHES/" \
    -e "s/^steps=.*/steps=$((MAX_BATCHES * 8 / 10)),$((MAX_BATCHES * 9 / 10))/" \
    -e "s/^burn_in=.*/burn_in=$((MAX_BATCHES < 1000 ? MAX_BATCHES / 10 + 1 : 1000))/" "$cfg" > "$train_cfg"

mkdir -p "$WORK/backup"
cat > "$WORK/person.data" <<DATA
classes = 1
train = $WORK/data/$SET.txt
valid = $WORK/data/$SET.txt
names = $WORK/data/classes.names
backup = $WORK/backup
DATA

# 3. Train (darknet prints one line per iteration: "<iter>: <loss>, <avg loss>, <lr> rate, <s> seconds, <images> images").
cd "$WORK"
"$DARKNET" detector train "$WORK/person.data" "$train_cfg" $PRETRAINED 2>&1 | tee "$WORK/train.log"

# 4. A model folder for the detector (test-time cfg: batch=1).
final="$WORK/backup/darknet19-yolov3-train_final.weights"
[ -f "$final" ] || final=$(ls -t "$WORK"/backup/*.weights 2>/dev/null | head -n 1)
[ -n "$final" ] && [ -f "$final" ] || die "darknet wrote no weights to $WORK/backup; see $WORK/train.log"
mkdir -p "$WORK/model"
cp "$cfg" "$WORK/model/darknet19-yolov3.cfg"
cp "$final" "$WORK/model/darknet19-yolov3.weights"
cp "$WORK/data/classes.names" "$WORK/model/person.names"
echo "trained model: $WORK/model (use: yolo_slam_detect --model $WORK/model IMAGE)"
