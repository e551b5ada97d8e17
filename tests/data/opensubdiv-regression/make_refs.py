#!/usr/bin/env python3
"""Packs OpenSubdiv reference outputs into this directory's compact form.

Input: a directory with, per shape, NAME.obj (the regression shape's OBJ text
with its `t` tags), NAME.L3.obj (level-3 points `v x y z` in Far's order,
faces, and `# hole K` lines) and NAME.limit.xyz (Far's Limit of the level-3
points), as written by the throwaway driver described in README.md.
Output: NAME.obj (copied) and NAME.ref.gz with the lines
    faces F        level-3 face count (hole faces included)
    holes H        level-3 hole faces
    v x y z        level-3 points (13 significant digits)
    l x y z        limit points
for every shape whose level 3 has at most --max-points points.
"""
import argparse, glob, gzip, os, shutil

ap = argparse.ArgumentParser()
ap.add_argument("src")
ap.add_argument("--out", default=os.path.dirname(os.path.abspath(__file__)))
ap.add_argument("--max-points", type=int, default=10000)
a = ap.parse_args()
kept, left = [], []
for l3 in sorted(glob.glob(os.path.join(a.src, "*.L3.obj"))):
    name = os.path.basename(l3)[: -len(".L3.obj")]
    v, faces, holes = [], 0, 0
    for line in open(l3):
        if line.startswith("v "):
            v.append(line.split()[1:4])
        elif line.startswith("f "):
            faces += 1
        elif line.startswith("# hole"):
            holes += 1
    if len(v) > a.max_points:
        left.append((name, len(v)))
        continue
    lim = [l.split() for l in open(os.path.join(a.src, name + ".limit.xyz")) if l.strip()]
    fmt = lambda p: " ".join("%.13g" % float(x) for x in p)
    text = f"faces {faces}\nholes {holes}\n" + "".join("v " + fmt(p) + "\n" for p in v)
    text += "".join("l " + fmt(p) + "\n" for p in lim)
    with gzip.GzipFile(os.path.join(a.out, name + ".ref.gz"), "wb", 9, mtime=0) as f:
        f.write(text.encode())
    shutil.copyfile(os.path.join(a.src, name + ".obj"), os.path.join(a.out, name + ".obj"))
    kept.append(name)
print(f"{len(kept)} shapes packed; left out (over {a.max_points} points): "
      + ", ".join(f"{n} ({k})" for n, k in left))
