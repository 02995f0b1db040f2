#!/usr/bin/python3
"""The issue-13 shadow matrix: scenes, one per light, each rendered with every filter and with
contact shadows off and on, scored against ../shared/truth (README there).

    python3 tests/truth-scenes/scenes.py          # (re)writes tests/truth-scenes/*.json

Each NAME.json is the scene the tracer sees (no shadow settings: they do not change the
truth, and the tracer's cache key covers the whole document); matrix.py adds the filter and
contact settings per row. Run from the repository root."""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))

# sphere r0.6 + 1 m box + 3 cm pole on a 12 m plane, camera [0, 6, 7] (tests/gpu/truth/*_pcss.json)
CASTERS = [{"shape": "plane", "size": [12, 12]},
           {"shape": "sphere", "radius": 0.6, "transform": {"translation": [-1.5, 0.6, 0]}},
           {"shape": "box", "size": [1, 1, 1], "transform": {"translation": [1.3, 0.5, 0.3]}},
           {"shape": "cylinder", "radius": 0.03, "height": 1.5, "transform": {"translation": [0, 0.75, 1.2]}}]
CAMERA = {"position": [0, 6, 7], "target": [0, 0, 0], "fov_y": 45}

POINT = {"type": "point", "position": [0.5, 3.0, -0.5], "intensity": 30}
SPOT = {"type": "spot", "position": [0.5, 3.5, 1.5], "direction": [-0.1, -1, -0.4], "outer_angle": 60,
        "intensity": 40}
SUN = {"type": "directional", "direction": [-0.5, -1, -0.3]}


def doc(objects, camera, light):
    return {"width": 128, "height": 128, "camera": camera, "objects": objects, "lights": [light],
            "output": {"debug": "shadow", "msaa": 1}}


def grazing():
    # the sun 7 degrees above the horizon: long shadows of a box, a 10 cm pole and a ball on a
    # 30 m plane (the scene of the last landing's note)
    el = math.radians(7)
    d = [-math.cos(el) * 0.8, -math.sin(el), -math.cos(el) * 0.6]
    objs = [{"shape": "plane", "size": [30, 30]},
            {"shape": "box", "size": [1, 1, 1], "transform": {"translation": [1.0, 0.5, 0.0]}},
            {"shape": "cylinder", "radius": 0.05, "height": 1.2, "transform": {"translation": [-1.0, 0.6, 1.0]}},
            {"shape": "sphere", "radius": 0.5, "transform": {"translation": [-1.5, 0.5, -1.5]}}]
    cam = {"position": [0, 5, 9], "target": [0, 0, -2], "fov_y": 50}
    return doc(objs, cam, {"type": "directional", "direction": d})


def street():
    # 200 m street, blocks on both sides, camera at head height looking down it: 4 cascades
    objs = [{"shape": "plane", "size": [40, 220], "transform": {"translation": [0, 0, -100]}}]
    for i in range(10):
        z = -i * 20.0
        h1, h2 = 6 + (i % 3) * 3, 9 - (i % 2) * 3
        objs.append({"shape": "box", "size": [4, h1, 8], "transform": {"translation": [-8, h1 / 2, z]}})
        objs.append({"shape": "box", "size": [4, h2, 8], "transform": {"translation": [8, h2 / 2, z - 10]}})
    cam = {"position": [0, 2.0, 8], "target": [0, 1.5, -40], "fov_y": 60, "far": 300}
    return doc(objs, cam, {"type": "directional", "direction": [0.6, -0.5, -0.3]})


def thin():
    # thin casters: a 1 cm sheet 0.25 m above the ground, a 1 cm wall standing on it, a 1.5 cm
    # rod lying on the ground, a 2 cm pole
    objs = [{"shape": "plane", "size": [8, 8]},
            {"shape": "box", "size": [1.0, 0.01, 0.7], "transform": {"translation": [-0.9, 0.25, 0.2]}},
            {"shape": "box", "size": [0.01, 0.6, 1.2], "transform": {"translation": [0.7, 0.3, -0.2]}},
            {"shape": "cylinder", "radius": 0.0075, "height": 1.2,
             "transform": {"translation": [0.0, 0.0075, 0.9], "rotation": [0, 0, 0.7071068, 0.7071068]}},
            {"shape": "cylinder", "radius": 0.01, "height": 0.8, "transform": {"translation": [0.1, 0.4, -0.6]}}]
    cam = {"position": [0, 3.2, 3.6], "target": [0, 0, 0], "fov_y": 45}
    return doc(objs, cam, {"type": "directional", "direction": [-0.6, -1, -0.4]})


def scenes():
    s = {}
    s["soft_sun"] = doc(CASTERS, CAMERA, dict(SUN, angular_diameter=3.0))
    s["soft_spot"] = doc(CASTERS, CAMERA, dict(SPOT, radius=0.25))
    s["soft_point"] = doc(CASTERS, CAMERA, dict(POINT, radius=0.3))
    s["hard_sun"] = doc(CASTERS, CAMERA, dict(SUN))
    s["hard_spot"] = doc(CASTERS, CAMERA, dict(SPOT))
    s["hard_point"] = doc(CASTERS, CAMERA, dict(POINT))
    s["grazing_sun"] = grazing()
    s["street"] = street()
    s["thin"] = thin()
    return s


# Per scene: shadow settings every row adds (the street asks for 4 cascades).
EXTRA = {"street": {"directional": {"mode": "cascades", "cascades": 4}}}

if __name__ == "__main__":
    for name, d in scenes().items():
        with open(os.path.join(HERE, name + ".json"), "w") as f:
            json.dump(d, f, indent=None)
            f.write("\n")
        print(name)
