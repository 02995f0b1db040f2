#!/usr/bin/env python3
"""tests/bench/farm_bench.py BUILD CORPUS [OUT] — the farm benchmark on new models (`make bench`,
section "farm: new models"; `make bench-farm` alone). CORPUS is a folder written by
tests/bench/farm_corpus.py (its manifest.json lists the models). In one run, one after the other:

  farm   BUILD/umbra-render thumb CORPUS/* -o OUT/farm/ --size 256: one warm process; per-model ms
         from its report.jsonl, images/s from the process's wall time (device set-up included);
         the first job of each thread (first use of the device) is left out of the per-format table.
  http   a fresh BUILD/umbrad on a free loopback port (cold: no model imported yet), every model
         POSTed once as multipart (part "scene" = {"preset": "thumbnail", "width": 256, "height":
         256, "objects": [{"shape": "model", "part": "m", "format": ...}]}, part "m" = the file)
         by 4 clients; per response its wall time and every Server-Timing entry (whatever the
         stage names are); images/s from the first send to the last answer; the daemon's RSS
         (VmRSS, VmHWM) when ready and after the run.
  f3d    `f3d --output` once per model (a new process each, no shadows: f3d 1.3 has none) under
         one `xvfb-run -a`; per-process ms; images/s from their sum.

Then prints images/s and the ratios farm/f3d and http/f3d, the medians of each Server-Timing
stage over all models and per size class (10k / 100k / 1M; a stage a response leaves out counts as
0 ms there, and a line says how many named it), and a table of median ms per class,
format and texture. Numbers only: nothing is asserted; a failed model is listed and left out of
the rates. Images, logs and results.json stay in OUT (or $FARM_BENCH_OUT; default: a temporary
folder, removed).
Env: FARM_BENCH_SIZE (256), FARM_BENCH_CONC (4), FARM_BENCH_F3D=0 (skip f3d),
     FARM_BENCH_UMBRAD_ARGS (extra umbrad flags, split on spaces), FARM_BENCH_F3D_TIMEOUT (120 s)."""
import concurrent.futures, http.client, json, os, re, shutil, signal, statistics, subprocess, sys, tempfile, time

SIZE = int(os.environ.get("FARM_BENCH_SIZE", "256"))
CONC = int(os.environ.get("FARM_BENCH_CONC", "4"))
CLASSES = ("10k", "100k", "1M")


def log(msg):
    print(msg, flush=True)


def median(xs):
    return statistics.median(xs) if xs else None


def fmt_ms(x):
    return "-" if x is None else ("%.0f" % x if x >= 100 else "%.1f" % x)


def table(head, rows, left=1):
    """A Markdown table, columns padded: the first `left` columns to the left, the rest to the right."""
    cells = [head] + [[str(c) for c in r] for r in rows]
    width = [max(len(r[i]) for r in cells) for i in range(len(head))]
    line = lambda r: "| " + " | ".join(c.rjust(w) if k >= left else c.ljust(w)
                                        for k, (c, w) in enumerate(zip(r, width))) + " |"
    out = [line(cells[0]), "|" + "|".join("-" * (w + 2) for w in width) + "|"]
    return "\n".join(out + [line(r) for r in cells[1:]])


# ---- farm ------------------------------------------------------------------------------------


def run_farm(build, models, out):
    d = os.path.join(out, "farm")
    os.makedirs(d, exist_ok=True)
    cmd = [os.path.join(build, "umbra-render"), "thumb"] + [m["path"] for m in models] + \
          ["-o", d + "/", "--size", str(SIZE), "--no-progress"]
    t0 = time.monotonic()
    p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.monotonic() - t0
    with open(os.path.join(out, "farm.log"), "w") as fh:
        fh.write(p.stderr)
    summary = [l for l in p.stderr.splitlines() if " of %d in " % len(models) in l]
    by_file = {}
    try:
        with open(os.path.join(d, "report.jsonl")) as fh:
            for line in fh:
                r = json.loads(line)
                by_file[r["file"]] = r
    except OSError as e:
        log("farm: no report (%s); exit %d; last lines:\n%s" % (e, p.returncode, "\n".join(p.stderr.splitlines()[-5:])))
    for m in models:
        r = by_file.get(m["path"], {})
        m["farm_status"] = r.get("status", "missing")
        m["farm_ms"] = r.get("ms") if r.get("status") == "ok" else None
        if m["farm_status"] != "ok":
            m.setdefault("failures", []).append("farm %s: %s" % (m["farm_status"], r.get("error")))
    # The first job of each thread also pays the thread's first use of the device (~300 ms on
    # lavapipe): marked, and left out of the per-format medians (not out of images/s).
    threads = re.search(r"(\d+) threads?\)", summary[-1]) if summary else None
    threads = int(threads.group(1)) if threads else (os.cpu_count() or 1)
    for m in models[:threads]:
        m["farm_first"] = True
    return {"wall": wall, "rc": p.returncode, "threads": threads,
            "summary": summary[-1].split(": ", 1)[-1] if summary else None}


# ---- http ------------------------------------------------------------------------------------


def vm_status(pid):
    out = {}
    try:
        with open("/proc/%d/status" % pid) as fh:
            for line in fh:
                k, _, v = line.partition(":")
                if k in ("VmRSS", "VmHWM"):
                    out[k] = int(v.split()[0]) // 1024
    except OSError:
        pass
    return out


def split_unquoted(text, sep):
    """text split on sep outside double-quoted strings (a desc="a, b" stays whole)."""
    out, cur, quoted, esc = [], [], False, False
    for ch in text:
        if esc:
            esc = False
        elif quoted and ch == "\\":
            esc = True
        elif ch == '"':
            quoted = not quoted
        elif ch == sep and not quoted:
            out.append("".join(cur))
            cur = []
            continue
        cur.append(ch)
    return out + ["".join(cur)]


def parse_server_timing(value):
    """Every entry of a Server-Timing header (RFC: name *( ";" param )), whatever its name:
    {name: dur ms}, None for an entry without a dur."""
    out = {}
    for entry in split_unquoted(value or "", ","):
        parts = [p.strip() for p in split_unquoted(entry, ";")]
        if not parts[0]:
            continue
        dur = None
        for p in parts[1:]:
            k, _, v = p.partition("=")
            if k.strip().lower() == "dur":
                try:
                    dur = float(v.strip().strip('"'))
                except ValueError:
                    pass
        out[parts[0]] = dur
    return out


def multipart(model, data, obj_extra=None):
    obj = {"shape": "model", "part": "m", "format": model["format"]}
    obj.update(obj_extra or {})
    scene = {"preset": "thumbnail", "width": SIZE, "height": SIZE, "objects": [obj]}
    boundary = "umbra-farm-bench-7c1d0e5a93b2"
    while boundary.encode() in data:
        boundary += "x"
    head = ("--%s\r\nContent-Disposition: form-data; name=\"scene\"\r\nContent-Type: application/json\r\n\r\n%s\r\n"
            "--%s\r\nContent-Disposition: form-data; name=\"m\"; filename=\"%s\"\r\n"
            "Content-Type: application/octet-stream\r\n\r\n") % (boundary, json.dumps(scene), boundary, model["file"])
    return head.encode() + data + ("\r\n--%s--\r\n" % boundary).encode(), "multipart/form-data; boundary=" + boundary


def post(port, model, out):
    with open(model["path"], "rb") as fh:
        body, ctype = multipart(model, fh.read())
    t0 = time.monotonic()
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=600)
    try:
        conn.request("POST", "/v1/render", body=body, headers={"Content-Type": ctype})
        r = conn.getresponse()
        data = r.read()
        ms = (time.monotonic() - t0) * 1000
        st, warn = r.getheader("Server-Timing"), r.getheader("Umbra-Warnings")
        status = r.status
    except (OSError, http.client.HTTPException) as e:
        return {"status": 0, "ms": None, "timing": {}, "error": str(e)}
    finally:
        conn.close()
    if status == 200:
        with open(os.path.join(out, os.path.splitext(model["file"])[0] + ".png"), "wb") as fh:
            fh.write(data)
    return {"status": status, "ms": ms, "timing": parse_server_timing(st), "warnings": warn, "t_end": time.monotonic(),
            "error": None if status == 200 else data[:300].decode("utf-8", "replace")}


def run_http(build, models, out):
    d = os.path.join(out, "http")
    os.makedirs(d, exist_ok=True)
    port_file = os.path.join(out, "umbrad.port")
    extra = os.environ.get("FARM_BENCH_UMBRAD_ARGS", "").split()
    errlog = open(os.path.join(out, "umbrad.log"), "w")
    daemon = subprocess.Popen([os.path.join(build, "umbrad"), "--listen", "127.0.0.1:0", "--port-file", port_file,
                               "--queue", "256", "--log-format", "json"] + extra, stdout=errlog, stderr=errlog)
    try:
        port, t0 = None, time.monotonic()
        while True:
            if daemon.poll() is not None:
                raise RuntimeError("umbrad exited %d before it was ready (see umbrad.log)" % daemon.returncode)
            if time.monotonic() - t0 > 180:
                raise RuntimeError("umbrad not ready after 180 s")
            if port is None and os.path.exists(port_file) and os.path.getsize(port_file):
                port = int(open(port_file).read().strip())
            if port is not None:
                try:
                    c = http.client.HTTPConnection("127.0.0.1", port, timeout=5)
                    c.request("GET", "/readyz")
                    ready = c.getresponse().status == 200
                    c.close()
                    if ready:
                        break
                except OSError:
                    pass
            time.sleep(0.1)
        rss_ready = vm_status(daemon.pid)
        t0 = time.monotonic()
        with concurrent.futures.ThreadPoolExecutor(CONC) as pool:
            results = list(pool.map(lambda m: post(port, m, d), models))
        ends = [r["t_end"] for r in results if r.get("t_end")]
        wall = (max(ends) if ends else time.monotonic()) - t0
        rss_after = vm_status(daemon.pid)
        # The trim to --max-rss follows each answer: one second for the last one's (the idle
        # trim waits --idle-trim, 30 s).
        time.sleep(1.0)
        rss_settled = vm_status(daemon.pid)
    finally:
        daemon.send_signal(signal.SIGTERM)
        try:
            rc = daemon.wait(60)
        except subprocess.TimeoutExpired:
            daemon.kill()
            rc = daemon.wait()
        errlog.close()
    for m, r in zip(models, results):
        m["http_status"], m["http_ms"], m["timing"] = r["status"], r["ms"] if r["status"] == 200 else None, r["timing"]
        if r["status"] != 200:
            m.setdefault("failures", []).append("http %d: %s" % (r["status"], r["error"]))
        if r.get("warnings"):
            m["http_warnings"] = r["warnings"]
    version = None
    with open(os.path.join(out, "umbrad.log")) as fh:
        for line in fh:
            if "starting" in line:
                try:
                    version = json.loads(line).get("msg", "").split(" starting")[0]
                except ValueError:
                    version = line.strip()[:80]
                break
    return {"wall": wall, "rss_ready": rss_ready, "rss_after": rss_after, "rss_settled": rss_settled, "exit": rc,
            "version": version}


# ---- f3d -------------------------------------------------------------------------------------


def run_f3d(models, out):
    f3d, xvfb = shutil.which("f3d"), shutil.which("xvfb-run")
    if os.environ.get("FARM_BENCH_F3D", "1") == "0" or not f3d or not xvfb:
        return None
    d = os.path.join(out, "f3d")
    os.makedirs(d, exist_ok=True)
    # --dry-run: no configuration file (a user's or /etc/f3d's would change what is drawn);
    # white background as the thumbnails; f3d's default camera and lights; no grid, no shadows.
    timeout = os.environ.get("FARM_BENCH_F3D_TIMEOUT", "120")
    script = os.path.join(out, "f3d-loop.sh")
    with open(script, "w") as fh:
        fh.write("i=0\nwhile read -r f o; do\n"
                 "  s=$(date +%%s%%N)\n"
                 "  timeout %s f3d --dry-run --resolution=%d,%d --bg-color=1,1,1 --output=\"$o\" \"$f\" "
                 ">>\"$F3D_LOG\" 2>&1\n"
                 "  rc=$?\n"
                 "  e=$(date +%%s%%N)\n"
                 "  echo \"$i $rc $(( (e - s) / 1000 ))\"\n"
                 "  i=$((i + 1))\ndone\n" % (timeout, SIZE, SIZE))
    lst = "".join("%s %s\n" % (m["path"], os.path.join(d, os.path.splitext(m["file"])[0] + ".png")) for m in models)
    env = dict(os.environ, F3D_LOG=os.path.join(out, "f3d.log"))
    p = subprocess.run([xvfb, "-a", "sh", script], input=lst, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       text=True, env=env)
    seen = 0
    for line in p.stdout.splitlines():
        parts = line.split()
        if len(parts) != 3 or not parts[0].isdigit():
            continue
        i, rc, us = int(parts[0]), int(parts[1]), int(parts[2])
        m = models[i]
        seen += 1
        png = os.path.join(d, os.path.splitext(m["file"])[0] + ".png")
        ok = rc == 0 and os.path.exists(png) and os.path.getsize(png) > 0
        m["f3d_ms"] = us / 1000 if ok else None
        if not ok:
            m.setdefault("failures", []).append("f3d exit %d%s" % (rc, "" if os.path.exists(png) else ", no image"))
    if seen != len(models):
        log("f3d: %d of %d processes reported (xvfb-run exit %d: %s)" % (seen, len(models), p.returncode,
                                                                        p.stderr.strip()[-300:]))
    return {"sum": sum(m.get("f3d_ms") or 0 for m in models) / 1000, "n": sum(1 for m in models if m.get("f3d_ms"))}


# ---- report ----------------------------------------------------------------------------------


def stage_names(models):
    names = []
    for m in models:
        for k in m.get("timing", {}):
            if k not in names:
                names.append(k)
    return names


def stage_value(m, k):
    t = m.get("timing") or {}
    if k == "(rest)":  # what total holds beyond the named stages
        if t.get("total") is None:
            return None
        return t["total"] - sum(v for n, v in t.items() if n != "total" and v is not None)
    return t.get(k)


def texture_label(t):
    """The manifest's "2048x2048 jpeg" as "jpeg 2048", "vertex colours" as "colours", none as "-"."""
    if not t:
        return "-"
    size, _, kind = t.partition(" ")
    return "%s %s" % (kind, size.split("x")[0]) if size[:1].isdigit() else t.split()[-1]


def report(models, farm, http_, f3d, out):
    n = len(models)
    ok_farm = [m for m in models if m.get("farm_ms") is not None]
    ok_http = [m for m in models if m.get("http_ms") is not None]
    rate_farm = len(ok_farm) / farm["wall"] if farm["wall"] else 0
    rate_http = len(ok_http) / http_["wall"] if http_ and http_["wall"] else 0
    rate_f3d = f3d["n"] / f3d["sum"] if f3d and f3d["sum"] else 0
    tris = sum(m["triangles"] for m in models)
    log("%d models, %.2f M triangles, %.0f MB of files; %dx%d, lavapipe/llvmpipe, %d CPUs" %
        (n, tris / 1e6, sum(m["bytes"] for m in models) / 1e6, SIZE, SIZE, os.cpu_count()))
    rows = [["farm (umbra-render thumb, 1 process)", "%d/%d" % (len(ok_farm), n), "%.1f" % farm["wall"],
             "%.2f" % rate_farm, "%.2f" % (rate_farm / rate_f3d) if rate_f3d else "-"]]
    if http_:
        rows.append(["http (umbrad, multipart, c=%d)" % CONC, "%d/%d" % (len(ok_http), n), "%.1f" % http_["wall"],
                     "%.2f" % rate_http, "%.2f" % (rate_http / rate_f3d) if rate_f3d else "-"])
    if f3d:
        rows.append(["f3d (a process per model, xvfb)", "%d/%d" % (f3d["n"], n), "%.1f" % f3d["sum"],
                     "%.2f" % rate_f3d, "1.00"])
    else:
        rows.append(["f3d", "-", "-", "not run (no f3d / xvfb-run, or FARM_BENCH_F3D=0)", "-"])
    log(table(["path", "ok", "s", "images/s", "/ f3d"], rows))
    if farm.get("summary"):
        log("farm's own summary: " + farm["summary"])
    first = [m for m in models if m.get("farm_first") and m.get("farm_ms") is not None]
    if first:
        log("farm: the first job of each thread (%s) is left out of the table below (first use of the device)" %
            ", ".join("%s %.0f ms" % (m["file"], m["farm_ms"]) for m in first))
    if http_:
        log("%s RSS ready %s MB (peak %s); after the run %s MB (peak VmHWM %s MB), 1 s later %s MB; exit %s" % (
            http_.get("version") or "umbrad", http_["rss_ready"].get("VmRSS", "?"), http_["rss_ready"].get("VmHWM", "?"),
            http_["rss_after"].get("VmRSS", "?"), http_["rss_after"].get("VmHWM", "?"),
            http_["rss_settled"].get("VmRSS", "?"), http_["exit"]))

        names = stage_names(ok_http)
        if "total" in names:
            names = [k for k in names if k != "total"] + ["(rest)", "total"]
        log("")
        log("Server-Timing medians, ms (c=%d; (rest) = total - the named stages), and the client's wall:" % CONC)
        srows, notes = [], []
        for cls in ("all",) + CLASSES:
            sel = [m for m in ok_http if cls == "all" or m["class"] == cls]
            if not sel:
                continue
            # A stage a response does not name took no time there (umbrad leaves out a stage of 0 ms:
            # no compile, no import for a cached model), so it counts as 0 in the median.
            srows.append([cls, str(len(sel))] + [fmt_ms(median([stage_value(m, k) or 0.0 for m in sel]))
                                                 for k in names] +
                         [fmt_ms(median([m["http_ms"] for m in sel]))])
            some = []
            for k in names:
                had = [v for v in (stage_value(m, k) for m in sel) if v]
                if 0 < len(had) < len(sel):
                    some.append("%s %d/%d (%s)" % (k, len(had), len(sel), fmt_ms(median(had))))
            if some:
                notes.append("%s: %s" % (cls, ", ".join(some)))
        log(table(["class", "n"] + names + ["wall"], srows))
        if notes:
            log("stages only some responses name (how many, their median ms); the table counts the rest as 0:")
            for line in notes:
                log("  " + line)

    log("")
    log("median ms per model by class, format and texture (farm: report.jsonl ms; http: wall at c=%d "
        "and Server-Timing total; f3d: the process):" % CONC)
    groups = {}
    for m in models:
        tex = texture_label(m.get("texture"))
        groups.setdefault((CLASSES.index(m["class"]), m["format"], tex), []).append(m)
    trows = []
    for (ci, fmt, tex), sel in sorted(groups.items()):
        trows.append([CLASSES[ci], fmt, tex, str(len(sel)), "%.0fk" % (median([m["triangles"] for m in sel]) / 1e3),
                      fmt_ms(median([m["farm_ms"] for m in sel if m.get("farm_ms") is not None
                                     and not m.get("farm_first")])),
                      fmt_ms(median([m["http_ms"] for m in sel if m.get("http_ms") is not None])),
                      fmt_ms(median([m["timing"]["total"] for m in sel
                                     if m.get("http_ms") is not None and m["timing"].get("total") is not None])),
                      fmt_ms(median([m["f3d_ms"] for m in sel if m.get("f3d_ms") is not None]))])
    log(table(["class", "format", "texture", "n", "tris", "farm", "http wall", "http total", "f3d"], trows, left=3))

    bad = [m for m in models if m.get("failures")]
    if bad:
        log("")
        log("failures:")
        for m in bad:
            for f in m["failures"]:
                log("  %s: %s" % (m["file"], f.replace("\n", " ")[:300]))
    warned = [m for m in models if m.get("http_warnings")]
    for m in warned:
        log("  %s: Umbra-Warnings: %s" % (m["file"], m["http_warnings"][:200]))
    with open(os.path.join(out, "results.json"), "w") as fh:
        json.dump({"farm": farm, "http": http_, "f3d": f3d, "models": models}, fh, indent=1, default=str)


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit("usage: farm_bench.py BUILD CORPUS [OUT]")
    build, corpus = sys.argv[1], sys.argv[2]
    with open(os.path.join(corpus, "manifest.json")) as fh:
        models = json.load(fh)["models"]
    for m in models:
        m["path"] = os.path.join(corpus, m["file"])
    out = sys.argv[3] if len(sys.argv) == 4 else os.environ.get("FARM_BENCH_OUT")
    keep = bool(out)
    out = out or tempfile.mkdtemp(prefix="farm-bench-")
    os.makedirs(out, exist_ok=True)
    try:
        t = time.monotonic()
        farm = run_farm(build, models, out)
        log("farm done in %.1f s" % (time.monotonic() - t))
        t = time.monotonic()
        http_ = run_http(build, models, out)
        log("http done in %.1f s" % (time.monotonic() - t))
        t = time.monotonic()
        f3d = run_f3d(models, out)
        log("f3d %s" % ("done in %.1f s" % (time.monotonic() - t) if f3d else "skipped"))
        log("")
        report(models, farm, http_, f3d, out)
    finally:
        if not keep:
            shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    main()
