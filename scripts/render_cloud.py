#!/usr/bin/env python3
"""Renders a coloured PLY cloud (yolo_slam_run --cloud) into two PNGs: a top view (orthographic,
looking down onto the floor) and a perspective view from above and behind the first camera.
The SLAM world is the first camera's frame (y down, but tilted with the camera): the floor is
found as the largest plane whose normal is within 45 degrees of y (seeded RANSAC) and the cloud
is rotated so that its normal is the vertical. Points are splatted with a z-buffer.

usage: render_cloud.py CLOUD.ply OUT_PREFIX [--size 800]  ->  OUT_PREFIX_top.png, OUT_PREFIX_perspective.png
"""
import argparse
import sys

import cv2
import numpy as np

PLY_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("r", "u1"), ("g", "u1"), ("b", "u1")])
EXPECTED_PROPS = ["float x", "float y", "float z", "uchar red", "uchar green", "uchar blue"]
BACKGROUND = 255
SPLAT_PX = 2          # half-size of a point's square in the picture
MARGIN = 0.05         # fraction of the picture left around the cloud
VIEW_FOV_DEG = 60.0   # perspective view's horizontal field of view
VIEW_BACK_M = 2.0     # perspective camera: behind the cloud's near edge
VIEW_UP_M = 2.0       # and above its top
FLOOR_TOLERANCE_M = 0.03
FLOOR_TRIALS = 300
FLOOR_MAX_TILT_COS = np.cos(np.radians(45.0))
BOUNDS_PERCENTILE = 1.0  # the top view's extent ignores this percentage of stray points per side


def read_ply(path):
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            sys.exit(f"error: {path}: not a PLY file; pass the file yolo_slam_run --cloud wrote")
        props, count, fmt = [], 0, None
        while True:
            line = f.readline()
            if not line:
                sys.exit(f"error: {path}: PLY header has no end_header")
            words = line.decode("ascii", "replace").split()
            if words[:1] == ["end_header"]:
                break
            if words[:1] == ["format"]:
                fmt = words[1]
            elif words[:2] == ["element", "vertex"]:
                count = int(words[2])
            elif words[:1] == ["property"]:
                props.append(" ".join(words[1:]))
        if fmt != "binary_little_endian" or props != EXPECTED_PROPS:
            sys.exit(f"error: {path}: expected binary little-endian x y z float, red green blue uchar")
        data = np.frombuffer(f.read(count * PLY_DTYPE.itemsize), dtype=PLY_DTYPE, count=count)
    xyz = np.stack([data["x"], data["y"], data["z"]], axis=1).astype(np.float64)
    rgb = np.stack([data["r"], data["g"], data["b"]], axis=1)
    return xyz, rgb


def splat(u, v, depth, rgb, size):
    """Nearest point wins per pixel (smaller depth drawn last)."""
    img = np.full((size, size, 3), BACKGROUND, np.uint8)
    order = np.argsort(-depth)
    u, v, rgb = u[order].astype(int), v[order].astype(int), rgb[order]
    for du in range(-SPLAT_PX, SPLAT_PX + 1):
        for dv in range(-SPLAT_PX, SPLAT_PX + 1):
            uu, vv = u + du, v + dv
            ok = (uu >= 0) & (uu < size) & (vv >= 0) & (vv < size)
            img[vv[ok], uu[ok]] = rgb[ok][:, ::-1]  # RGB -> BGR for OpenCV
    return img


def floor_rotation(xyz):
    """Rotation taking the floor's normal to +y (down), identity when no floor plane is found."""
    rng = np.random.default_rng(0)
    best, best_n = 0, None
    for _ in range(FLOOR_TRIALS):
        a, b, c = xyz[rng.choice(len(xyz), 3, replace=False)]
        n = np.cross(b - a, c - a)
        if np.linalg.norm(n) < 1e-9:
            continue
        n /= np.linalg.norm(n)
        if n[1] < 0:
            n = -n
        if n[1] < FLOOR_MAX_TILT_COS:
            continue
        inliers = np.count_nonzero(np.abs((xyz - a) @ n) < FLOOR_TOLERANCE_M)
        # The floor is the plane below the others: prefer it among planes of similar support.
        if inliers > best:
            best, best_n = inliers, n
    if best_n is None:
        return np.eye(3)
    y = best_n
    x = np.cross(y, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    z = np.cross(x, y)
    return np.stack([x, y, z])


def top_view(xyz, rgb, size):
    x, z = xyz[:, 0], xyz[:, 2]
    lo = np.percentile(np.stack([x, z], axis=1), BOUNDS_PERCENTILE, axis=0)
    hi = np.percentile(np.stack([x, z], axis=1), 100 - BOUNDS_PERCENTILE, axis=0)
    scale = (1 - 2 * MARGIN) * size / max(hi - lo)
    mid = (lo + hi) / 2
    u = size / 2 + (x - mid[0]) * scale
    v = size / 2 - (z - mid[1]) * scale  # far (large z) at the top
    return splat(u, v, xyz[:, 1], rgb, size)  # smallest y (highest point) wins


def perspective_view(xyz, rgb, size):
    centre = np.median(xyz, axis=0)
    eye = np.array([centre[0], xyz[:, 1].min() - VIEW_UP_M, xyz[:, 2].min() - VIEW_BACK_M])
    forward = centre - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, -1.0, 0.0])
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    R = np.stack([right, down, forward])  # world -> view rows
    p = (xyz - eye) @ R.T
    keep = p[:, 2] > 0.1
    p, rgb = p[keep], rgb[keep]
    f = size / 2 / np.tan(np.radians(VIEW_FOV_DEG) / 2)
    u = size / 2 + f * p[:, 0] / p[:, 2]
    v = size / 2 + f * p[:, 1] / p[:, 2]
    return splat(u, v, p[:, 2], rgb, size)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("cloud")
    ap.add_argument("out_prefix")
    ap.add_argument("--size", type=int, default=800)
    a = ap.parse_args()
    xyz, rgb = read_ply(a.cloud)
    if len(xyz) < 3:
        sys.exit(f"error: {a.cloud}: the cloud is empty; was the dense map on and tracking ok?")
    xyz = xyz @ floor_rotation(xyz).T
    for name, img in (("top", top_view(xyz, rgb, a.size)), ("perspective", perspective_view(xyz, rgb, a.size))):
        out = f"{a.out_prefix}_{name}.png"
        if not cv2.imwrite(out, img):
            sys.exit(f"error: {out}: cannot write; check the folder exists")
        print(f"wrote {out}")


if __name__ == "__main__":
    main()
