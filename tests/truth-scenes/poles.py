#!/usr/bin/python3
"""Thin poles on a ground (issue 31: thin-pole contact), rendered with contact shadows and scored
against the ray-traced truth (../shared/truth; traced once per scene, cached in build/truth-cache).

    /usr/bin/python3 tests/truth-scenes/poles.py [--render BIN] [--out DIR] [--only SUBSTR,...]
        [--json FILE] [--compare FILE] [--all] [--contact off,on] [--res 256,default]

A case is a pole (radius 0.5-4 cm, 1.2 m, upright or leaning 25 degrees) on a 10 m plane under one
light (a sun hard or 0.5 / 2 degrees wide, a spot or point light hard or 5 cm in radius; the
light 20-70 degrees above the ground, from behind, beside or in front of the pole as the camera
sees it), seen from 1.5 m, 2.5 m or 6 m, 128 x 128, rendered with shadows.resolution 256 and the
default. The default set is a spread of the whole product (every value of every axis appears);
--all renders the product. Prints one row per render: missing_contact / rmse / false_core and,
with --compare, the earlier run's figures before each. Rows over the issue's bound
(missing_contact 0.10, false_core 0.002) are marked *."""
import argparse
import itertools
import json
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
TRUTH = os.environ.get("UMBRA_TRUTH", os.path.join(ROOT, "..", "shared", "truth"))
sys.path.insert(0, TRUTH)
import score as sc  # noqa: E402

RADII = [0.005, 0.01, 0.02, 0.04]
LIGHTS = ["sun", "sun0.5", "sun2", "spot", "spot5cm", "point", "point5cm"]
ELEVATIONS = [20, 45, 70]
AZIMUTHS = {"behind": 0, "side": 90, "front": 160}   # 0: light behind the pole, shadow towards the camera
POSES = ["up", "lean"]
CAMERAS = {"close": 1.5, "near": 2.5, "far": 6.0}
HEIGHT = 1.2


def light_doc(kind, el, az):
    e, a = math.radians(el), math.radians(az)
    to_light = [math.cos(e) * math.sin(a), math.sin(e), -math.cos(e) * math.cos(a)]
    if kind.startswith("sun"):
        d = {"type": "directional", "direction": [-c for c in to_light]}
        if kind != "sun":
            d["angular_diameter"] = float(kind[3:])
        return d
    dist = 3.0
    pos = [c * dist for c in to_light]
    d = {"type": kind.replace("5cm", ""), "position": pos, "intensity": 30}
    if d["type"] == "spot":
        d["direction"] = [-c for c in to_light]
        d["outer_angle"] = 40
    if kind.endswith("5cm"):
        d["radius"] = 0.05
    return d


def pole_doc(r, pose):
    if pose == "up":
        return {"shape": "cylinder", "radius": r, "height": HEIGHT, "transform": {"translation": [0, HEIGHT / 2, 0]}}
    a = math.radians(25)   # leaning to +x (across the view), its foot's centre on the ground
    return {"shape": "cylinder", "radius": r, "height": HEIGHT,
            "transform": {"translation": [math.sin(a) * HEIGHT / 2, math.cos(a) * HEIGHT / 2, 0],
                          "rotation": [0, 0, -math.sin(a / 2), math.cos(a / 2)]}}


def scene(r, kind, el, az, pose, cam):
    dist = CAMERAS[cam]
    camera = {"position": [0, dist * 0.55, dist], "target": [0, 0.25, 0], "fov_y": 40}
    return {"width": 128, "height": 128, "camera": camera,
            "objects": [{"shape": "plane", "size": [10, 10]}, pole_doc(r, pose)],
            "lights": [light_doc(kind, el, AZIMUTHS[az])], "output": {"debug": "shadow", "msaa": 1}}


def cases(full):
    axes = [RADII, LIGHTS, ELEVATIONS, list(AZIMUTHS), POSES, list(CAMERAS)]
    if full:
        return list(itertools.product(*axes))
    # a spread: every light x radius, the other axes cycling, so each value of each axis appears
    out = []
    for i, (kind, r) in enumerate(itertools.product(LIGHTS, RADII)):
        out.append((r, kind, ELEVATIONS[i % 3], list(AZIMUTHS)[(i // 3) % 3], POSES[(i // 2) % 2],
                    list(CAMERAS)[(i // 4) % 3]))
    return out


def name(c):
    r, kind, el, az, pose, cam = c
    return "pole-r%g-%s-e%d-%s-%s-%s" % (r * 100, kind, el, az, pose, cam)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--render", default=os.path.join(ROOT, "build", "umbra-render"))
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "truth-poles"))
    ap.add_argument("--only", help="comma-separated substrings of case names")
    ap.add_argument("--all", action="store_true", help="the whole product of the axes")
    ap.add_argument("--contact", default="on", help="off,on")
    ap.add_argument("--res", default="256,default", help="shadows.resolution values")
    ap.add_argument("--json", help="write the rows as JSON lines here")
    ap.add_argument("--compare", help="rows of an earlier --json run: print before -> after")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    jobs = []
    for c in cases(a.all):
        n = name(c)
        if a.only and not any(s in n for s in a.only.split(",")):
            continue
        base = scene(*c)
        sp = os.path.join(a.out, n + ".json")
        with open(sp, "w") as fh:
            json.dump(base, fh)
        for res in a.res.split(","):
            for con in a.contact.split(","):
                d = json.loads(json.dumps(base))
                sh = {"contact": {"enabled": con == "on"}}
                if res != "default":
                    sh["resolution"] = int(res)
                d["lights"][0]["shadow"] = sh
                tag = "%s-%s-c%d" % (n, res, con == "on")
                p = os.path.join(a.out, tag + ".render.json")
                with open(p, "w") as fh:
                    json.dump(d, fh)
                jobs.append((n, res, con, tag, p, sp))
    subprocess.run([a.render] + [j[4] for j in jobs] + ["-o", a.out + "/", "-j", "1", "--no-progress"],
                   check=False, stdout=subprocess.DEVNULL)
    old = {}
    if a.compare:
        with open(a.compare) as fh:
            old = {(r["case"], r["res"], r["contact"]): r for r in map(json.loads, fh)}
    cwd = os.getcwd()
    os.chdir(ROOT)
    rows = []
    for n, res, con, tag, p, sp in jobs:
        png = os.path.join(a.out, tag + ".render.png")
        if not os.path.exists(png):
            print("%s %s %s: no render" % (n, res, con))
            continue
        m = sc.score(sp, png, diff=os.path.join(a.out, tag + ".diff.png"))
        m.update({"case": n, "res": res, "contact": con})
        rows.append(m)
        b = old.get((n, res, con))
        cell = lambda k, fmt: ((fmt % b[k]) + " -> " if b else "") + (fmt % m[k])
        flag = "*" if m["missing_contact"] > 0.10 or m["false_core"] > 0.002 else " "
        print("%s %-48s %-7s %-3s mc %s  rmse %s  fc %s  (%d contact px)" % (
            flag, n, res, con, cell("missing_contact", "%.3f"), cell("rmse", "%.4f"),
            cell("false_core", "%.4f"), m["contact_shadow_px"]), flush=True)
    os.chdir(cwd)
    if a.json:
        with open(a.json, "w") as fh:
            for r in rows:
                fh.write(json.dumps(r) + "\n")
    bad = [r for r in rows if r["missing_contact"] > 0.10 or r["false_core"] > 0.002]
    print("%d rows, %d over a bound (missing_contact 0.10, false_core 0.002)" % (len(rows), len(bad)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
