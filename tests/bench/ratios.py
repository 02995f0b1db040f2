#!/usr/bin/env python3
"""The ratio table of `make bench` (issue 12): reads the logs tests/bench.sh left in DIR and
prints, per target, umbra's figure, the figure it is compared with, their ratio, the goal and
whether it is met. Only ratios of figures taken side by side in one run mean anything on a
shared machine, so every row divides two numbers from the same run.

Logs (any may be missing; its rows then say "not run"):
  floor.txt   build/floor/limits --steps c, in rounds between umbra's (and the older build's) rows
  warm.txt    build/tests/bench: thumb-256, thumb-512, thumb256-colour-100k/10k (rounds; the last two
              with -s, a new model's sun map every run), studio-spots, studio-16lights,
              model-1m-path, model-1m
  cold.txt    lines "run i: png X ms, exr+aov Y ms"
  http-ratio.txt  tests/bench/http_bench.sh: thumb-256 at concurrency 4, 600 requests, and the
              fresh daemon's "umbrad RSS ..." lines (ready: the warm figure)
  http.txt    tests/bench/http_bench.sh over every bench scene (make bench, not bench-quick): its
              RSS after those rows
  http-inproc.txt  build/tests/bench: thumb-256 just before and just after the HTTP rows (the
              in-process rate the HTTP rate is divided by, so that both see the same load)
  warm-before.txt, cold-before.txt   the same from an older build (BENCH_BEFORE), for "before"
Usage: ratios.py DIR [before]"""
import os, re, statistics, sys

d = sys.argv[1]
before = len(sys.argv) > 2 and sys.argv[2] == "before"


def read(name):
    p = os.path.join(d, name)
    return open(p).read() if os.path.exists(p) else ""


def floor_ms(msaa):
    """The floor's step c at MSAA 1 or 4: the median over its runs (bench.sh runs it in rounds
    between umbra's rows, and the older build's)."""
    v = [float(m.group(1)) for m in
         re.finditer(r"^\| c +\| one submit: .*MSAA%d .*?\| +([0-9.]+) \|" % msaa, read("floor.txt"), re.M)]
    return statistics.median(v) if v else None


def warm_total(scene, log=None):
    """build/tests/bench's median total (ms) of SCENE in LOG (default warm.txt): the median
    over every row of that name (one per round)."""
    v = []
    for line in read(log or ("warm-before.txt" if before else "warm.txt")).splitlines():
        f = line.split()
        if len(f) >= 8 and f[0] == scene:
            v.append(float(f[7]))
    return statistics.median(v) if v else None


def cold(kind):
    v = [float(x) for x in re.findall(r"%s ([0-9]+) ms" % re.escape(kind), read("cold-before.txt" if before else "cold.txt"))]
    return statistics.median(v) if v else None


def http_rate(scene, conc):
    for line in ("" if before else read("http-ratio.txt")).splitlines():
        f = line.split()
        if len(f) >= 5 and f[0] == scene and f[1] == str(conc):
            return float(f[4])
    return None


def rss_mb(which, log):
    m = re.search(r"^umbrad RSS %s: ([0-9]+) kB" % which, "" if before else read(log), re.M)
    return int(m.group(1)) / 1024.0 if m else None


def row(target, a, a_txt, b, b_txt, goal, better):
    """better: 'le' (ratio must be <= goal) or 'ge'."""
    if a is None or b is None or b == 0:
        print("%-42s %14s %20s %7s %7s %s" % (target, a_txt(a) if a is not None else "not run",
                                             b_txt(b) if b is not None else "not run", "-", goal, "not measured"))
        return
    r = a / b
    if goal is None:   # not one of the targets: shown for what it costs
        print("%-42s %14s %20s %7.2f %7s %s" % (target, a_txt(a), b_txt(b), r, "-", "(not a target)"))
        return
    met = r <= goal if better == "le" else r >= goal
    print("%-42s %14s %20s %7.2f %7s %s" % (target, a_txt(a), b_txt(b), r,
                                           ("<= " if better == "le" else ">= ") + str(goal), "yes" if met else "NO"))


ms = lambda v: "%.1f ms" % v
fl4, fl1 = floor_ms(4), floor_ms(1)
t512, t256 = warm_total("thumb-512.json"), warm_total("thumb-256.json")
print("== ratio table (issue 12)%s: figures taken side by side in this run, warm medians"
      % (" BEFORE (the older build; HTTP and RSS not run for it)" if before else ""))
print("floor step c: MSAA 4 %s, MSAA 1 %s" % (ms(fl4) if fl4 else "not run", ms(fl1) if fl1 else "not run"))
print("%-42s %14s %20s %7s %7s %s" % ("target", "umbra", "compared with", "ratio", "goal", "met"))
row("thumb-512 / floor c MSAA 4", t512, ms, fl4, lambda v: "floor " + ms(v), 1.0, "le")
row("thumb-256 / floor c MSAA 4", t256, ms, fl4, lambda v: "floor " + ms(v), 0.5, "le")
# Issue 28: a new model's 256² thumbnail (its shadow map drawn every run), 100k triangles with
# smooth vertex colours (its level is refused for colour: drawn in full), against the floor's whole step c.
row("new 100k model, full detail, 256² / floor c", warm_total("thumb256-colour-100k.json"), ms, fl4,
    lambda v: "floor " + ms(v), 1.0, "le")
row("new 10k model, 256² / floor c", warm_total("thumb256-colour-10k.json"), ms, fl4, lambda v: "floor " + ms(v),
    None, "le")
row("studio-spots / thumb-512", warm_total("studio-spots.json"), ms, t512, lambda v: "thumb-512 " + ms(v), 2.5, "le")
row("16 shadowed lights / thumb-512", warm_total("studio-16lights.json"), ms, t512, lambda v: "thumb-512 " + ms(v),
    4.0, "le")
row("1M-tri model, cached, by path / thumb-512", warm_total("model-1m-path.json"), ms, t512,
    lambda v: "thumb-512 " + ms(v), 4.0, "le")
# The 1M-triangle target is the cached import (the row above); a client that sends the
# model inline pays for 66 MB of JSON as well.
row("1M-tri model, inline base64 / thumb-512", warm_total("model-1m.json"), ms, t512,
    lambda v: "thumb-512 " + ms(v), None, "le")
row("cold CLI EXR+AOV / cold PNG", cold("exr+aov"), ms, cold("png"), lambda v: "png " + ms(v), 2.0, "le")
t256_http = None if before else warm_total("thumb-256.json", "http-inproc.txt")
t256_rate = 1000.0 / t256_http if t256_http else 1000.0 / t256 if t256 else None
row("HTTP thumb-256 4 clients / in-process", http_rate("thumb-256.json", 4), lambda v: "%.1f img/s" % v, t256_rate,
    lambda v: "in-proc %.1f img/s" % v, 1.0, "ge")
# The memory target is the warm daemon (ready, default flags); what it holds after
# serving every bench scene (cached maps, each pipeline variant lavapipe compiled) is shown for
# what it is: --idle-trim gives the maps and free pages back after 30 s idle.
rss = rss_mb("ready", "http-ratio.txt")
row("warm umbrad RSS (ready, default flags)", rss, lambda v: "%.0f MB" % v, 200.0 if rss is not None else None,
    lambda v: "%.0f MB" % v, 1.0, "le")
after = rss_mb("after", "http.txt")
if after is not None:
    row("umbrad RSS after every scene's HTTP rows", after, lambda v: "%.0f MB" % v, 200.0, lambda v: "%.0f MB" % v,
        None, "le")
