#!/usr/bin/env python3
"""tests/http/explain_check.py — checks of an `explain` answer for tests/http/explain.sh.

  explain_check.py plan FILE                  FILE is a plan (api/explain.schema.json), not analyzed
  explain_check.py multipart BODY CTYPE IMAGE BODY is multipart/mixed (boundary from CTYPE): an
                                              image part byte-equal to IMAGE, then an analyzed plan
                                              whose counts equal what the render measured
  explain_check.py get FILE PATH              prints a value of a plan ("totals.shadow_texels",
                                              "shadow_maps.0.resolution")
Exit 0 when it holds; the reason on stdout as "# ..." otherwise. The schema is checked with
python3-jsonschema (Debian), an implementation nobody here wrote.
"""
import json
import sys

import jsonschema

SCHEMA = json.load(open("api/explain.schema.json"))


def fail(msg):
    print("# " + msg)
    sys.exit(1)


def valid(doc):
    try:
        jsonschema.Draft202012Validator(SCHEMA).validate(doc)
    except jsonschema.ValidationError as e:
        fail("schema: %s at %s" % (e.message, "/".join(str(p) for p in e.absolute_path)))


def parts(body, ctype):
    params = dict(p.strip().split("=", 1) for p in ctype.split(";")[1:] if "=" in p)
    if not ctype.startswith("multipart/mixed") or "boundary" not in params:
        fail("not multipart/mixed with a boundary: %r" % ctype)
    delim = b"--" + params["boundary"].encode()
    chunks = body.split(b"\r\n" + delim)
    first = chunks[0]
    if not first.startswith(delim + b"\r\n"):
        fail("the body does not open with the boundary")
    chunks[0] = first[len(delim) + 2:]
    if not chunks[-1].startswith(b"--"):
        fail("no closing boundary")
    out = []
    for c in chunks[:-1]:
        c = c[2:] if c.startswith(b"\r\n") else c
        head, _, data = c.partition(b"\r\n\r\n")
        headers = dict(l.split(": ", 1) for l in head.decode().split("\r\n"))
        out.append((headers, data))
    return out


def main():
    mode = sys.argv[1]
    if mode == "get":
        v = json.load(open(sys.argv[2]))
        for k in sys.argv[3].split("."):
            v = v[int(k)] if isinstance(v, list) else v[k]
        print(v)
        return
    if mode == "plan":
        doc = json.load(open(sys.argv[2]))
        valid(doc)
        if doc["analyzed"] or "actual" in doc:
            fail("a plan alone says it was analyzed")
        return
    ps = parts(open(sys.argv[2], "rb").read(), sys.argv[3])
    if len(ps) != 2:
        fail("%d parts, not 2" % len(ps))
    (ih, image), (jh, plan) = ps
    if ih.get("Content-Type") != "image/png" or image != open(sys.argv[4], "rb").read():
        fail("the image part (%s) is not the plain render's bytes" % ih.get("Content-Type"))
    if jh.get("Content-Type") != "application/json":
        fail("the plan part is %s" % jh.get("Content-Type"))
    doc = json.loads(plan)
    valid(doc)
    t, a = doc["totals"], doc.get("actual", {})
    if not doc["analyzed"]:
        fail("not analyzed")
    for k in ("shadow_maps_drawn", "shadow_texels", "shadow_triangles", "camera_triangles", "sphere_proxies"):
        if t[k] != a.get(k):
            fail("%s: the plan says %s, the render %s" % (k, t[k], a.get(k)))
    if not all(v.get("actual_ms") for v in doc["views"]):
        fail("a view without its measured times")


main()
