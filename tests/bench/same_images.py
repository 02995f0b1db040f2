#!/usr/bin/env python3
"""tests/bench/same_images.py OLD_BUILD NEW_BUILD [WORK_DIR] — renders one set of scenes with two
builds' umbra-render and compares the images byte for byte: the proof a refactor asks for ("no
image changes"). The set: the bench scenes (../shared/bench) and their variants
(tests/bench/variants.py: filters, contact shadows, directional modes, 1/4/16 spot lights,
outputs PNG 8/16 and EXR with AOVs, a 16-view turntable, 10k/100k-triangle models), the truth
scenes (tests/truth-scenes), scenes written here for the decisions the render plan makes (debug
views, several views, planes that may or may not shadow, alpha-masked casters, a low sun, spheres
drawn as proxies and with exact segments) and thumbnails of 12 generated models
(tests/cli/gen_models.py) at 256 and 512, opaque and transparent.
Exit 0 when every image is the same; 1 lists those that differ. Env: SHARED (../shared)."""
import copy, glob, json, os, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def extra_scenes(out, bench):
    """Scenes for the plan's decisions that the bench set leaves out."""
    thumb = json.load(open(os.path.join(bench, "thumb-256.json")))
    outdoor = json.load(open(os.path.join(bench, "outdoor-csm.json")))
    def save(name, doc):
        json.dump(doc, open(os.path.join(out, name + ".json"), "w"))
    for dbg in ("shadow", "cascades", "normals", "depth", "atlas"):
        d = copy.deepcopy(outdoor)
        d["output"] = {"debug": dbg}
        save("dbg-" + dbg, d)
    d = copy.deepcopy(thumb)
    d["views"] = [{"fit": "objects", "direction": [1, -0.5, 0.2]}, {"position": [4, 3, 4], "target": [0, 0.8, 0]},
                  {"type": "orthographic", "height": 4, "position": [0, 6, 0.01], "target": [0, 0, 0]}]
    save("views3", d)
    d = copy.deepcopy(thumb)                       # a second plane above the ground: planes judged
    d["objects"].append({"shape": "plane", "size": [1, 1], "transform": {"translation": [1.5, 2.5, 0]}})
    d["objects"].append({"shape": "box", "size": [0.5, 0.5, 0.5], "transform": {"translation": [-1, -0.1, 1]}})
    save("planes", d)
    d = copy.deepcopy(thumb)                       # low sun: non-square fit
    d["lights"][0]["direction"] = [-1, -0.12, -0.2]
    save("low-sun", d)
    d = copy.deepcopy(thumb)
    d["materials"]["leaf"] = {"base_color": [0.2, 0.7, 0.2, 0.3], "alpha_mode": "mask", "alpha_cutoff": 0.2}
    d["objects"].append({"shape": "box", "size": [1, 0.05, 1], "material": "leaf", "transform": {"translation": [1, 2, 0.5]}})
    save("masked", d)
    d = copy.deepcopy(thumb)
    d["lights"] = [{"type": "spot", "position": [2, 4, 1], "direction": [-0.4, -1, -0.2], "radius": 0.2},
                   {"type": "point", "position": [-2, 3, 2], "intensity": 30},
                   {"type": "directional", "direction": [0.3, -1, 0.4], "shadow": {"filter": "vsm"}}]
    save("three-lights", d)
    d = copy.deepcopy(thumb)
    d["objects"][1]["segments"] = 24
    d["camera"]["fov_y"] = 20
    save("coarse-sphere", d)
    d = copy.deepcopy(thumb)
    d["width"], d["height"] = 640, 360
    d["output"] = {"format": "png", "msaa": 1}
    d["shadows"] = {"filter": "pcf", "pcf_radius": 4, "resolution": 1024}
    save("wide-pcf", d)
    # The environment's directions and pass (the plan's since the merge of 'env'): the studio
    # over the plane ground (directions below it only weighed), a turned studio behind the
    # scene, a masked caster (no environment pass), 20 directions at 256 texels.
    d = copy.deepcopy(thumb)
    d["environment"] = {"map": {"preset": "studio"}}
    save("env-studio", d)
    d = copy.deepcopy(thumb)
    d["environment"] = {"map": {"preset": "studio", "rotation": 1.2}, "background": "map"}
    d["lights"] = []
    save("env-turned", d)
    d = copy.deepcopy(thumb)
    d["environment"] = {"map": {"preset": "studio"}, "shadow": {"directions": 20, "resolution": 256}}
    d["materials"]["leaf"] = {"base_color": [0.2, 0.7, 0.2, 0.3], "alpha_mode": "mask", "alpha_cutoff": 0.2}
    d["objects"].append({"shape": "box", "size": [1, 0.05, 1], "material": "leaf", "transform": {"translation": [1, 2, 0.5]}})
    save("env-masked", d)


def thumbs(out):
    models = os.path.join(out, "models")
    subprocess.run([sys.executable, os.path.join(ROOT, "tests/cli/gen_models.py"), models, "12"], check=True,
                   stdout=subprocess.DEVNULL)
    return sorted(glob.glob(os.path.join(models, "*")))


def render(build, scenes, models, asset_root, out):
    exe = os.path.join(build, "umbra-render")
    os.makedirs(out, exist_ok=True)
    bad = []
    for s in scenes:
        name = os.path.splitext(os.path.basename(s))[0]
        doc = json.load(open(s))
        ext = "exr" if (doc.get("output") or {}).get("format") == "exr" else "png"
        r = subprocess.run([exe, s, "-o", os.path.join(out, name + "." + ext), "--asset-root", asset_root],
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if r.returncode:
            bad.append("%s: exit %d %s" % (name, r.returncode, r.stderr.strip()[:200]))
    for size in (256, 512):
        for transparent in (False, True):
            d = os.path.join(out, "thumb-%d%s" % (size, "-t" if transparent else ""))
            args = [exe, "thumb"] + models + ["-o", d + "/", "--size", str(size), "-j", "1", "--no-progress"]
            if transparent:
                args.append("--transparent")
            subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            for rep in glob.glob(os.path.join(d, "report*.jsonl")):
                os.remove(rep)   # times differ
    return bad


def main():
    old, new = sys.argv[1], sys.argv[2]
    work = sys.argv[3] if len(sys.argv) > 3 else tempfile.mkdtemp(prefix="same-images-")
    shared = os.environ.get("SHARED", os.path.join(ROOT, "..", "shared"))
    bench = os.path.join(shared, "bench")
    scenes_dir = os.path.join(work, "scenes")
    os.makedirs(scenes_dir, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(HERE, "variants.py"), bench, scenes_dir], check=True)
    for f in glob.glob(os.path.join(scenes_dir, "model-1m*")):
        os.remove(f)   # minutes of import on lavapipe for no other decision
    extra_scenes(scenes_dir, bench)
    scenes = sorted(glob.glob(os.path.join(bench, "*.json")) + glob.glob(os.path.join(scenes_dir, "*.json")) +
                    glob.glob(os.path.join(ROOT, "tests/truth-scenes/*.json")))
    models = thumbs(work)
    fails = []
    for tag, build in (("old", old), ("new", new)):
        fails += ["%s %s" % (tag, b) for b in render(build, scenes, models, scenes_dir, os.path.join(work, tag))]
    same, differ, missing = 0, [], []
    for dirpath, _, files in os.walk(os.path.join(work, "old")):
        for f in sorted(files):
            a = os.path.join(dirpath, f)
            b = os.path.join(work, "new", os.path.relpath(a, os.path.join(work, "old")))
            if not os.path.exists(b):
                missing.append(b)
            elif open(a, "rb").read() == open(b, "rb").read():
                same += 1
            else:
                differ.append(os.path.relpath(a, os.path.join(work, "old")))
    print("%d images the same, %d differ, %d missing, %d failed renders (%s)" % (same, len(differ), len(missing),
                                                                                  len(fails), work))
    for d in differ + missing + fails:
        print("  " + d)
    return 0 if not differ and not missing and not fails and same > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
