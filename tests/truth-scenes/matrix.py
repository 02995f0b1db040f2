#!/usr/bin/python3
"""Renders the issue-13 matrix (every scene of tests/truth-scenes x filter x contact off/on) with
build/umbra-render and scores it against the ray-traced truth (../shared/truth: traced once per
scene, cached in build/truth-cache; renders and diff images in build/truth-matrix/).

    /usr/bin/python3 tests/truth-scenes/matrix.py [--render BIN] [--out DIR] [--only NAME,...]
        [--json FILE] [--extra-shadow JSON]

Prints a Markdown table: rmse / iou / disagree_core / missing_contact / false_core per row, and
for pcss rows the penumbra high-frequency energy (mean squared Laplacian of the visibility over
the reference's penumbra pixels, 0.05 < v < 0.95, candidate vs reference). Targets (issue 13,
pcss on soft lights, the default filter on hard ones) are marked * when missed."""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
TRUTH = os.environ.get("UMBRA_TRUTH", os.path.join(ROOT, "..", "shared", "truth"))
sys.path.insert(0, TRUTH)
sys.path.insert(0, HERE)
import score as sc  # noqa: E402
import trace as tr  # noqa: E402
import pngio  # noqa: E402
import scenes as S  # noqa: E402

SOFT = ["soft_sun", "soft_spot", "soft_point"]
ORDER = ["soft_sun", "soft_spot", "soft_point", "hard_sun", "hard_spot", "hard_point", "grazing_sun",
         "street", "thin"]
FILTERS = ["default", "pcf", "pcss", "vsm", "evsm"]


def variants(name):
    for f in FILTERS:
        if f == "default" and name in SOFT:
            continue            # the default of a soft light is pcss
        for contact in (False, True):
            yield f, contact


def variant_doc(base, name, filt, contact, extra):
    d = json.loads(json.dumps(base))
    sh = dict(S.EXTRA.get(name, {}))
    sh.update(extra)
    if filt != "default":
        sh["filter"] = filt
    sh["contact"] = {"enabled": contact}
    d["lights"][0]["shadow"] = sh
    return d


def hf_energy(v, pen):
    lap = 4 * v[1:-1, 1:-1] - v[:-2, 1:-1] - v[2:, 1:-1] - v[1:-1, :-2] - v[1:-1, 2:]
    m = pen[1:-1, 1:-1]
    return float((lap[m] ** 2).mean()) if m.any() else 0.0


def targets(name, filt, contact, m):
    """Names of the issue's targets this row misses (only rows the targets apply to)."""
    soft = name in SOFT
    if (soft and filt != "pcss") or (not soft and filt != "default"):
        return None
    miss = []
    if m["rmse"] > 0.02: miss.append("rmse")
    if m["iou"] < 0.95: miss.append("iou")
    if m["disagree_core"] > 0.002: miss.append("disagree_core")
    if m["missing_contact"] > (0.02 if contact else 0.05): miss.append("missing_contact")
    if m["false_core"] > 0.002: miss.append("false_core")
    return miss


def print_compare(path, rows):
    """Before -> after per row; contact on folded into off where both runs agree on it."""
    with open(path) as fh:
        old = {(r["scene"], r["filter"], r["contact"]): r for r in map(json.loads, fh)}
    keys = [("rmse", "%.4f"), ("iou", "%.3f"), ("disagree_core", "%.4f"), ("missing_contact", "%.4f"),
            ("false_core", "%.4f")]
    new = {(r["scene"], r["filter"], r["contact"]): r for r in rows if "error" not in r}
    print("\n| scene | filter | contact | " + " | ".join(k for k, _ in keys) + " |")
    print("|---|---|---|" + "---|" * len(keys))
    for k, r in new.items():
        b = old.get(k)
        if b is None:
            continue
        off = (k[0], k[1], False)
        if k[2] and off in new and off in old and all(
                new[off][m] == r[m] and old[off][m] == b[m] for m, _ in keys):
            continue    # same as contact off, shown there as "off = on"
        same_on = not k[2] and (k[0], k[1], True) in new and all(
            new[(k[0], k[1], True)][m] == r[m] and old.get((k[0], k[1], True), {}).get(m) == b[m] for m, _ in keys)
        cells = []
        for m, fmt in keys:
            cell = (fmt % b[m]) if b[m] == r[m] else (fmt % b[m]) + " → " + (fmt % r[m])
            if r.get("miss") and m in r["miss"]:
                cell += "*"
            cells.append(cell)
        print("| %s | %s | %s | %s |" % (k[0], k[1], "off = on" if same_on else ("on" if k[2] else "off"),
                                          " | ".join(cells)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--render", default=os.path.join(ROOT, "build", "umbra-render"))
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "truth-matrix"))
    ap.add_argument("--only", help="comma-separated scene names")
    ap.add_argument("--filters", help="comma-separated filters (default: all)")
    ap.add_argument("--json", help="also write the rows as JSON lines here")
    ap.add_argument("--extra-shadow", default="{}", help="JSON merged into every light's shadow")
    ap.add_argument("--compare", help="rows of an earlier --json run: print before -> after")
    a = ap.parse_args()
    names = a.only.split(",") if a.only else ORDER
    filters = a.filters.split(",") if a.filters else FILTERS
    extra = json.loads(a.extra_shadow)
    os.makedirs(a.out, exist_ok=True)
    bases = S.scenes()
    jobs = []
    for n in names:
        for f, c in variants(n):
            if f not in filters:
                continue
            tag = "%s-%s-%s" % (n, f, "c1" if c else "c0")
            p = os.path.join(a.out, tag + ".json")
            with open(p, "w") as fh:
                json.dump(variant_doc(bases[n], n, f, c, extra), fh)
            jobs.append((n, f, c, tag, p))
    subprocess.run([a.render] + [j[4] for j in jobs] + ["-o", a.out + "/", "-j", "1", "--no-progress"],
                   check=False, stdout=subprocess.DEVNULL)
    cwd = os.getcwd()
    os.chdir(ROOT)   # the truth cache is build/truth-cache
    rows = []
    for n, f, c, tag, p in jobs:
        scene = os.path.join(HERE, n + ".json")
        png = os.path.join(a.out, tag + ".png")
        if not os.path.exists(png):
            rows.append({"scene": n, "filter": f, "contact": c, "error": "no render"})
            continue
        out = sc.score(scene, png, diff=os.path.join(a.out, tag + ".diff.png"))
        cache = tr.get_truth(scene)
        truth, mask, gedge, _ = tr.load_truth(cache, 0)
        cand = pngio.read_image(png)
        valid = mask & ~gedge
        pen = valid & (truth > 0.05) & (truth < 0.95)
        out.update({"scene": n, "filter": f, "contact": c, "hf": hf_energy(cand, pen),
                    "hf_ref": hf_energy(truth, pen), "miss": targets(n, f, c, out)})
        rows.append(out)
    os.chdir(cwd)
    print("| scene | filter | contact | rmse | iou | disagree_core | missing_contact | false_core | penumbra HF (ref) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if "error" in r:
            print("| %s | %s | %s | %s |" % (r["scene"], r["filter"], "on" if r["contact"] else "off", r["error"]))
            continue
        miss = r["miss"] or []
        cell = lambda k, fmt: (fmt % r[k]) + ("*" if k in miss else "")
        hf = "%.4f (%.4f)" % (r["hf"], r["hf_ref"]) if r["filter"] == "pcss" and r["scene"] in SOFT else ""
        print("| %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            r["scene"], r["filter"], "on" if r["contact"] else "off", cell("rmse", "%.4f"), cell("iou", "%.3f"),
            cell("disagree_core", "%.4f"), cell("missing_contact", "%.4f"), cell("false_core", "%.4f"), hf))
    if a.compare:
        print_compare(a.compare, rows)
    if a.json:
        with open(a.json, "w") as fh:
            for r in rows:
                fh.write(json.dumps(r) + "\n")
    missed = [r for r in rows if r.get("miss")]
    print("\n%d rows; %d target rows missed: %s" % (len(rows), len(missed), ", ".join(
        "%s/%s/%s: %s" % (r["scene"], r["filter"], "on" if r["contact"] else "off", " ".join(r["miss"]))
        for r in missed) or "none"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
