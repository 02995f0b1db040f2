#!/usr/bin/env python3
"""tests/readme/check.py README URL TMP — runs every command of the README as a user would.

The commands are the README's fenced code blocks; the info string of each says how it is run:
  ```sh           each command (a line, with `\\` continuations and multi-line quotes) runs to
                  completion and must exit 0; the images and reports it writes must decode
                  (PNG, WebP, AVIF through avifdec, EXR by its magic; every report line "ok"),
                  and the files it names (-o NAME, > NAME) must exist.
  ```console      `$ COMMAND` lines, each followed by its output: the command runs, and when
                  the output shown is JSON, every member shown must be in the real output with
                  the same value (the problem+json and its pointer); else the text must match.
  ```python       the snippet runs (python3, clients/python on PYTHONPATH); exit 0, its images
                  must decode.
  ```sh server    each command starts a server that runs until stopped (make run, umbrad,
                  make cluster): it is started on a free port of its own, GET /readyz must
                  answer 200 and GET /v1/info its JSON, its log is JSON where it says
                  UMBRA_LOG_FORMAT=json; then it is stopped as Ctrl-C or SIGTERM would (SIGINT
                  to make's child, SIGTERM to umbrad) and must exit 0.
  ```sh manual    a command that cannot run here (an install, a long benchmark, deploying to
                  Kubernetes, make test itself, make clean): each must have an entry in COVERS
                  below, which checks it another way (the same script with fewer runs, the
                  suite of make test that runs the same script, the files kubectl would read).
A block with another info string, a command in an indented (unfenced) code block, or a manual
command without a cover fails the suite. In prose, each `make TARGET` must be a target
(`make -n`).

Where: commands starting with `make` run in the checkout; the others in TMP/w, which holds
build/ (the checkout's $BUILD; under ASan, scripts that preload the driver as the suites do),
clients/, deploy/, and the files the commands name (tests/readme/fixtures.py); ../shared is
$SHARED. 127.0.0.1:8080 in a command becomes the address of the suite's daemon (URL), or of
the server's own free port in a server block (and UMBRA_LISTEN / CLUSTER_PORT in make's
environment, for the targets that listen on 8080 by default). Standard library only.
"""
import http.client, json, os, re, shlex, shutil, signal, socket, subprocess, sys, time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "cli"))
sys.path.insert(0, os.path.join(HERE, "..", "util"))
import fixtures  # noqa: E402
import png  # noqa: E402
import webp  # noqa: E402

REPO = os.getcwd()
BUILD = os.environ.get("BUILD", "build")
SHARED = os.path.abspath(os.environ.get("SHARED", "../shared"))
ASAN = bool(os.environ.get("ASAN"))
PRELOAD = os.environ.get("DAEMON_PRELOAD", "")
START_TIMEOUT = float(os.environ.get("START_TIMEOUT", "240"))
DEFAULT = "127.0.0.1:8080"
counts = [0, 0]


def ok(name):
    counts[0] += 1
    print("ok - " + name, flush=True)


def nok(name, why=""):
    counts[1] += 1
    print("FAIL - %s%s" % (name, ": " + why if why else ""), flush=True)


def short(cmd):
    one = " ".join(cmd.split())
    return "`%s`" % (one if len(one) <= 90 else one[:87] + "...")


# ---- the README's blocks and commands ----

def blocks(text):
    """(line, info, lines) of each fenced block; (line, None, [line]) for an indented code line
    that starts a paragraph (an unfenced code block)."""
    out, lines, i, prev_blank = [], text.split("\n"), 0, True
    while i < len(lines):
        m = re.match(r"^```(.*)$", lines[i])
        if m:
            start, body = i + 1, []
            i += 1
            while i < len(lines) and not lines[i].startswith("```"):
                body.append(lines[i])
                i += 1
            out.append((start, m.group(1).strip(), body))
        elif prev_blank and lines[i].startswith("    ") and lines[i].strip():
            out.append((i + 1, None, [lines[i]]))
        prev_blank = not lines[i].strip()
        i += 1
    return out


def complete(text):
    if text.rstrip().endswith("\\"):
        return False
    try:
        shlex.split(text, comments=True)
        return True
    except ValueError:   # a quote still open: the command goes on
        return False


def commands(lines):
    """The commands of a sh block: comment-only lines dropped, continuations joined."""
    out, acc = [], ""
    for line in lines:
        if not acc and (not line.strip() or line.strip().startswith("#")):
            continue
        acc += line + "\n"
        if complete(acc):
            out.append(acc.strip())
            acc = ""
    if acc:
        out.append(acc.strip())
    return out


def console(lines):
    """(command, expected output) pairs of a console block."""
    out, cmd, expect, in_cmd = [], None, [], False
    for line in lines:
        if line.startswith("$ ") and not in_cmd:
            if cmd is not None:
                out.append((cmd, "\n".join(expect)))
            cmd, expect, in_cmd = line[2:] + "\n", [], True
        elif in_cmd:
            cmd += line + "\n"
        else:
            expect.append(line)
        if in_cmd and complete(cmd):
            in_cmd = False
    if cmd is not None:
        out.append((cmd, "\n".join(expect)))
    return out


# ---- running ----

def env_for(extra=None):
    env = {k: v for k, v in os.environ.items() if not k.startswith("MAKE") and k not in ("MFLAGS", "LD_PRELOAD")}
    env.update(extra or {})
    return env


def run(cmd, cwd, env=None, timeout=900):
    try:
        r = subprocess.run(["sh", "-c", cmd], cwd=cwd, env=env or env_for(), capture_output=True, timeout=timeout)
        return r.returncode, r.stdout.decode(errors="replace"), r.stderr.decode(errors="replace")
    except subprocess.TimeoutExpired:
        return -1, "", "timed out after %d s" % timeout


def snapshot(root):
    seen = {}
    for d, dirs, files in os.walk(root):
        for f in files:
            p = os.path.join(d, f)
            st = os.lstat(p)
            seen[p] = (st.st_mtime_ns, st.st_size)
    return seen


def check_file(path):
    """None when the file is what its name says, else why not."""
    name = path.lower()
    try:
        if name.endswith(".png"):
            w, h, _, _ = png.read(path)
            return None if w and h else "empty PNG"
        if name.endswith(".webp"):
            webp.info(open(path, "rb").read())
        elif name.endswith(".avif"):
            r = subprocess.run(["avifdec", "--info", path], capture_output=True)
            if r.returncode != 0:
                return "avifdec cannot read it"
        elif name.endswith(".exr"):
            if open(path, "rb").read(4) != b"\x76\x2f\x31\x01":
                return "no EXR magic"
        elif name.endswith(".jsonl") and os.path.basename(name).startswith("report"):
            for line in open(path):
                st = json.loads(line).get("status")
                if st != "ok":
                    return "a report line says %s: %s" % (st, line.strip()[:160])
    except (OSError, ValueError, SystemExit) as e:
        return str(e) or type(e).__name__
    return None


def named_outputs(cmd):
    try:
        toks = shlex.split(cmd, comments=True)
    except ValueError:
        return []
    return [toks[i + 1] for i, t in enumerate(toks[:-1]) if t in ("-o", ">")]


def check_outputs(cmd, cwd, before):
    """(images checked, problems) of what the command wrote."""
    after, bad, n = snapshot(cwd), [], 0
    for p, st in sorted(after.items()):
        if before.get(p) == st:
            continue
        why = check_file(p)
        if why:
            bad.append("%s: %s" % (os.path.relpath(p, cwd), why))
        elif re.search(r"\.(png|webp|avif|exr)$", p, re.I):
            n += 1
    for o in named_outputs(cmd):
        p = os.path.join(cwd, o)
        if not os.path.exists(p) or (os.path.isdir(p) and not os.listdir(p)):
            bad.append("%s was not written" % o)
    return n, bad


def plain(cmd, w, url):
    local = cmd.replace(DEFAULT, url[len("http://"):])
    cwd = REPO if cmd.startswith("make") else w
    before = snapshot(cwd) if cwd == w else {}
    rc, out, err = run(local, cwd)
    if rc != 0:
        return nok(short(cmd), "exit %d; %s" % (rc, (err or out).strip()[-400:]))
    n, bad = check_outputs(cmd, cwd, before) if cwd == w else (0, [])
    if bad:
        return nok(short(cmd), "; ".join(bad)[:600])
    ok("%s: exit 0%s" % (short(cmd), ", %d image%s decode%s" % (n, "s" * (n != 1), "s" * (n == 1)) if n else ""))


def subset(expect, got):
    if isinstance(expect, dict):
        return isinstance(got, dict) and all(k in got and subset(v, got[k]) for k, v in expect.items())
    return expect == got


def console_cmd(cmd, expect, w, url):
    rc, out, err = run(cmd.replace(DEFAULT, url[len("http://"):]), w)
    try:
        want = json.loads(expect)
    except ValueError:
        want = None
    if want is None:
        good = out.strip() == expect.strip()
    else:
        try:
            good = subset(want, json.loads(out))
        except ValueError:
            good = False
    if rc == 0 and good:
        ok("%s: its output as shown%s" % (short(cmd), " (%s)" % ", ".join(sorted(want)) if isinstance(want, dict) else ""))
    else:
        nok(short(cmd), "exit %d; shown %s; got %s" % (rc, " ".join(expect.split())[:200], (out or err).strip()[:300]))


def python_block(lines, w, url):
    path = os.path.join(w, "snippet.py")
    with open(path, "w") as f:
        f.write("\n".join(lines).replace(DEFAULT, url[len("http://"):]) + "\n")
    before = snapshot(w)
    env = env_for({"PYTHONPATH": os.path.join(REPO, "clients", "python")})
    r = subprocess.run([sys.executable, path], cwd=w, env=env, capture_output=True, timeout=600)
    os.unlink(path)
    name = "python: " + short(lines[-1] if lines else "")
    if r.returncode != 0:
        return nok(name, "exit %d; %s" % (r.returncode, r.stderr.decode(errors="replace")[-400:]))
    n, bad = check_outputs("", w, before)
    if bad or not n:
        return nok(name, "; ".join(bad) or "wrote no image")
    ok("%s: exit 0, %d image%s decode%s" % (name, n, "s" * (n != 1), "s" * (n == 1)))


# ---- servers ----

def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def get(port, path):
    try:
        c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
        c.request("GET", path)
        r = c.getresponse()
        return r.status, r.read()
    except OSError:
        return 0, b""


def children(pid):
    out = []
    for d in os.listdir("/proc"):
        try:
            if d.isdigit() and int(open("/proc/%s/stat" % d).read().rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(d))
        except (OSError, ValueError, IndexError):
            pass
    return out


def server(cmd, w, log):
    """Starts, checks and stops one server command; ok or nok."""
    toks = shlex.split(cmd, comments=True)
    extra = {}
    while toks and re.match(r"^[A-Z_][A-Z0-9_]*=", toks[0]):
        k, v = toks.pop(0).split("=", 1)
        extra[k] = os.path.expandvars(v.replace("$PWD", w))
    port, stats = free_port(), free_port()
    toks = [t.replace(DEFAULT, "127.0.0.1:%d" % port) for t in toks]
    extra = {k: v.replace(DEFAULT, "127.0.0.1:%d" % port) for k, v in extra.items()}
    is_make = toks[0] == "make"
    if is_make:
        if ASAN:
            print("# skipped under ASan: %s (the plain build runs it in make test)" % short(cmd))
            return
        if "cluster" in toks and not shutil.which("haproxy"):
            print("# skipped: %s needs haproxy" % short(cmd))
            return
        extra.update({"BUILD": BUILD, "UMBRA_LISTEN": "127.0.0.1:%d" % port, "CLUSTER_PORT": str(port),
                      "CLUSTER_STATS_PORT": str(stats)})
    elif PRELOAD:
        extra["LD_PRELOAD"] = PRELOAD
    cwd = REPO if is_make else w
    port_file = toks[toks.index("--port-file") + 1] if "--port-file" in toks else None
    if port_file:
        port_file = os.path.join(cwd, port_file)
        if os.path.exists(port_file):
            os.unlink(port_file)
    with open(log, "wb") as logf:
        proc = subprocess.Popen(toks, cwd=cwd, env=env_for(extra), stdout=logf, stderr=subprocess.STDOUT,
                                start_new_session=True)
    why, t0 = None, time.time()
    try:
        while True:
            if port_file and os.path.exists(port_file) and open(port_file).read().strip():
                port = int(open(port_file).read())
            if get(port, "/readyz")[0] == 200:
                break
            if proc.poll() is not None or time.time() - t0 > START_TIMEOUT:
                why = "never ready (exit %s)" % proc.poll()
                break
            time.sleep(0.25)
        if not why:
            st, body = get(port, "/v1/info")
            if st != 200 or "version" not in json.loads(body or b"{}"):
                why = "GET /v1/info answered %d" % st
            elif "cluster" in toks and get(stats, "/stats")[0] != 200:
                why = "no HAProxy stats page on port %d" % stats
        if not why and extra.get("UMBRA_LOG_FORMAT") == "json":
            for line in open(log, errors="replace"):
                if line.strip() and not line.lstrip().startswith("{"):
                    why = "a log line that is not JSON: " + line.strip()[:120]
                    break
        # Stop it as a user would: Ctrl-C to what make started, SIGTERM to umbrad.
        targets = children(proc.pid) if is_make else [proc.pid]
        for t in targets:
            os.kill(t, signal.SIGINT if is_make else signal.SIGTERM)
        rc = proc.wait(timeout=180)
        if not why and rc != 0:
            why = "exit %d after %s" % (rc, "Ctrl-C (SIGINT)" if is_make else "SIGTERM")
    except (subprocess.TimeoutExpired, OSError, ValueError) as e:
        why = why or "%s" % (e,)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    if why:
        tail = open(log, errors="replace").read().strip().splitlines()[-8:]
        return nok(short(cmd), why + "; log: " + " | ".join(tail)[-600:])
    ok("%s: ready in %.0f s, /v1/info answered, exit 0 when stopped" % (short(cmd), time.time() - t0))


# ---- manual commands: each checked another way ----

def make_n(*args):
    r = subprocess.run(["make", "-n"] + list(args), cwd=REPO, env=env_for({"BUILD": BUILD}), capture_output=True,
                       text=True, timeout=300)
    return r.returncode, r.stdout + r.stderr


def recipe_has(target, *needles):
    rc, out = make_n(*target.split())
    missing = [n for n in needles if n not in out]
    return rc == 0 and not missing, "make -n %s: exit %d%s" % (target, rc, ", lacks " + ", ".join(missing) if missing else "")


def in_make_test(script):
    return script in open(os.path.join(REPO, "tests", "run.sh")).read()


def cover_make_test(cmd):
    good, why = recipe_has("test", "tests/run.sh")
    return good and in_make_test("tests/readme/run.sh"), "this suite runs inside it (tests/run.sh); " + why


def cover_fuzz_long(cmd):
    fb = os.environ.get("FUZZ_BUILD", "")
    if fb and os.access(os.path.join(fb, "fuzz_http"), os.X_OK):
        rc, out, err = run("sh tests/fuzz/long.sh 300 fuzz_http", REPO, env_for({"FUZZ_BUILD": fb}), timeout=600)
        return rc == 0 and "fuzz_http" in out, "the same script, 300 executions of fuzz_http: exit %d" % rc
    return recipe_has("fuzz-long FUZZ_RUNS=1000000", "tests/fuzz/long.sh 1000000")


def cover_fuzz(cmd):
    fb = os.environ.get("FUZZ_BUILD", "")
    srcs = [f[:-2] for f in os.listdir(os.path.join(REPO, "tests", "fuzz")) if re.match(r"fuzz_.*\.c$", f)]
    if fb and os.path.isdir(fb):
        missing = [s for s in srcs if not os.access(os.path.join(fb, s), os.X_OK)]
        return not missing, "make test ran it: %d targets in %s%s" % (len(srcs), fb, ", missing " + ", ".join(missing) if missing else "")
    return recipe_has("fuzz", "fuzz-targets")


def cover_k8s(cmd):
    checked = in_make_test("deploy/check.sh") and "deploy/k8s/check.py" in open(os.path.join(REPO, "deploy", "check.sh")).read()
    kust = open(os.path.join(REPO, "deploy", "k8s", "kustomization.yaml")).read()
    res = re.findall(r"^\s*-\s*(\S+\.yaml)\s*$", kust, re.M)
    missing = [r for r in res if not os.path.exists(os.path.join(REPO, "deploy", "k8s", r))]
    return bool(checked and res and not missing), "make test's deploy suite checks deploy/k8s; kustomization lists %d files%s" % (
        len(res), ", missing " + ", ".join(missing) if missing else "")


def cover_soak(cmd):
    good, why = recipe_has("soak", "tests/http/soak.sh")
    return good and in_make_test("tests/http/soak.sh"), why + "; make test runs the same script, 1,000 requests"


COVERS = {
    "make test": cover_make_test,
    "make test-asan": lambda c: recipe_has("test-asan", "ASAN=1 sh tests/run.sh"),
    "make bench": lambda c: recipe_has("bench", "sh tests/bench.sh"),
    "make fuzz": cover_fuzz,
    "make fuzz-long": cover_fuzz_long,
    "sh tests/fuzz/long.sh": cover_fuzz_long,
    "make soak": cover_soak,
    "make clean": lambda c: recipe_has("clean", "rm -rf " + BUILD),
    "kubectl apply -k deploy/k8s": cover_k8s,
}


def manual(cmd):
    key = max((k for k in COVERS if cmd == k or cmd.startswith(k + " ")), key=len, default=None)
    if not key:
        return nok(short(cmd), "a manual command with no cover in tests/readme/check.py COVERS")
    good, why = COVERS[key](cmd)
    if good:
        ok("%s (manual): %s" % (short(cmd), why))
    else:
        nok(short(cmd), why)


def prose_make_targets(text):
    prose = re.sub(r"```.*?```", "", text, flags=re.S)
    for t in sorted(set(re.findall(r"`make( [^`]*)?`", prose))):
        args = t.strip()
        rc, out = make_n(*args.split())
        name = "prose `make%s`" % t
        ok(name + ": a target (make -n)") if rc == 0 else nok(name, out.strip()[-300:])


# ---- the scratch folder ----

def scratch(tmp):
    w = os.path.join(tmp, "w")
    os.makedirs(w)
    os.symlink(SHARED, os.path.join(tmp, "shared"))
    for d in ("clients", "deploy"):
        os.symlink(os.path.join(REPO, d), os.path.join(w, d))
    build = os.path.abspath(BUILD)
    if PRELOAD:
        os.makedirs(os.path.join(w, "build"))
        for b in ("umbra-render", "umbrad"):
            with open(os.path.join(w, "build", b), "w") as f:
                f.write('#!/bin/sh\nLD_PRELOAD="%s" exec "%s/%s" "$@"\n' % (PRELOAD, build, b))
            os.chmod(os.path.join(w, "build", b), 0o755)
    else:
        os.symlink(build, os.path.join(w, "build"))
    fixtures.make(w)
    return w


def main():
    readme, url, tmp = sys.argv[1], sys.argv[2], sys.argv[3]
    text = open(readme).read()
    w = scratch(tmp)
    seen = 0
    for line, info, body in blocks(text):
        seen += 1
        where = "%s:%d" % (readme, line)
        if info is None:
            nok("%s: an indented code block" % where, "commands go in fenced blocks (```sh, see check.py)")
        elif info == "sh":
            for c in commands(body):
                plain(c, w, url)
        elif info == "sh server":
            for i, c in enumerate(commands(body)):
                server(c, w, os.path.join(tmp, "server-%d-%d.log" % (line, i)))
        elif info == "sh manual":
            for c in commands(body):
                manual(c)
        elif info == "console":
            for c, expect in console(body):
                console_cmd(c, expect, w, url)
        elif info == "python":
            python_block(body, w, url)
        else:
            nok("%s: a block of kind %r" % (where, info), "not one this suite knows how to run")
    prose_make_targets(text)
    if seen < 10:
        nok("the README's blocks", "only %d found" % seen)
    print("%d passed, %d failed" % tuple(counts))
    sys.exit(1 if counts[1] else 0)


if __name__ == "__main__":
    main()
