#!/usr/bin/python3
"""Convert PASCAL VOC annotations to Darknet YOLO labels for the classes to train.

For every image id listed in <VOC>/ImageSets/Main/<set>.txt, reads <VOC>/Annotations/<id>.xml
and writes <OUT>/labels/<id>.txt with one line per kept object:
    <class index> <centre x> <centre y> <width> <height>     (all in [0,1] of the image)
and links the image to <OUT>/images/<id>.<ext> (Darknet finds a label by replacing "images" with
"labels" and the extension with .txt in the image path). Writes <OUT>/<set>.txt listing the
images. Objects marked difficult are skipped unless --keep-difficult. Standard library only.
"""
import argparse
import os
import sys
import xml.etree.ElementTree as ET

IMAGE_EXTS = (".jpg", ".jpeg", ".png", ".JPG", ".JPEG", ".PNG")


def fail(msg):
    print("error: " + msg, file=sys.stderr)
    sys.exit(1)


def find_image(voc, image_id):
    for ext in IMAGE_EXTS:
        p = os.path.join(voc, "JPEGImages", image_id + ext)
        if os.path.isfile(p):
            return p
    return None


def convert(voc, image_set, classes, out, keep_difficult):
    list_path = os.path.join(voc, "ImageSets", "Main", image_set + ".txt")
    if not os.path.isfile(list_path):
        fail(list_path + " not found; is " + voc + " a VOC folder (Annotations/, JPEGImages/, ImageSets/Main/)?")
    with open(list_path) as f:
        ids = [line.split()[0] for line in f if line.strip()]
    os.makedirs(os.path.join(out, "images"), exist_ok=True)
    os.makedirs(os.path.join(out, "labels"), exist_ok=True)
    listed, objects = [], 0
    for image_id in ids:
        xml_path = os.path.join(voc, "Annotations", image_id + ".xml")
        try:
            root = ET.parse(xml_path).getroot()
        except (OSError, ET.ParseError) as e:
            fail("%s: %s; fix or remove %s from %s" % (xml_path, e, image_id, list_path))
        size = root.find("size")
        try:
            w = float(size.find("width").text)
            h = float(size.find("height").text)
        except (AttributeError, TypeError, ValueError):
            fail(xml_path + ": <size> needs numeric <width> and <height>")
        if w <= 0 or h <= 0:
            fail(xml_path + ": image size must be positive")
        lines = []
        for obj in root.findall("object"):
            name = (obj.findtext("name") or "").strip()
            if name not in classes:
                continue
            if not keep_difficult and (obj.findtext("difficult") or "0").strip() == "1":
                continue
            bb = obj.find("bndbox")
            try:
                x1, y1, x2, y2 = (float(bb.find(k).text) for k in ("xmin", "ymin", "xmax", "ymax"))
            except (AttributeError, TypeError, ValueError):
                fail(xml_path + ": object '" + name + "' needs numeric bndbox xmin/ymin/xmax/ymax")
            # VOC boxes are 1-based inclusive pixels; clip and normalise.
            x1, y1 = max(x1 - 1, 0.0), max(y1 - 1, 0.0)
            x2, y2 = min(x2, w), min(y2, h)
            if x2 <= x1 or y2 <= y1:
                fail(xml_path + ": object '" + name + "' has an empty box")
            lines.append("%d %.6f %.6f %.6f %.6f" % (classes.index(name), (x1 + x2) / 2 / w,
                                                    (y1 + y2) / 2 / h, (x2 - x1) / w, (y2 - y1) / h))
            objects += 1
        image = find_image(voc, image_id)
        if image is None:
            fail("no image for " + image_id + " in " + os.path.join(voc, "JPEGImages"))
        link = os.path.join(out, "images", image_id + os.path.splitext(image)[1].lower())
        if os.path.lexists(link):
            os.remove(link)
        os.symlink(os.path.abspath(image), link)
        with open(os.path.join(out, "labels", image_id + ".txt"), "w") as f:
            f.write("".join(l + "\n" for l in lines))
        listed.append(os.path.abspath(link))
    return listed, objects


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--voc", action="append", required=True, help="VOC folder (repeatable, e.g. VOC2007 and VOC2012)")
    ap.add_argument("--set", default="trainval", help="image set name under ImageSets/Main (default trainval)")
    ap.add_argument("--classes", default="person", help="comma-separated class names to keep (default person)")
    ap.add_argument("--out", required=True, help="output folder (images/, labels/, <set>.txt)")
    ap.add_argument("--keep-difficult", action="store_true")
    a = ap.parse_args()
    classes = [c.strip() for c in a.classes.split(",") if c.strip()]
    if not classes:
        fail("--classes is empty")
    out = os.path.abspath(a.out)
    # Darknet maps an image path to its label by replacing the first "images" in it.
    if "images" in os.path.dirname(out):
        fail("--out " + out + " must not contain 'images' in its parent folders (Darknet would look for labels elsewhere)")
    listed, objects = [], 0
    for voc in a.voc:
        l, o = convert(voc, a.set, classes, out, a.keep_difficult)
        listed += l
        objects += o
    if not listed:
        fail("no images listed in the given VOC sets")
    with open(os.path.join(out, a.set + ".txt"), "w") as f:
        f.write("".join(p + "\n" for p in listed))
    with open(os.path.join(out, "classes.names"), "w") as f:
        f.write("".join(c + "\n" for c in classes))
    print("%d images, %d objects of %s -> %s" % (len(listed), objects, ",".join(classes), out))


if __name__ == "__main__":
    main()
