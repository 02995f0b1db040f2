#!/usr/bin/env python3
"""tests/http/conn.py — connection limits, timeouts and HTTP framing of umbrad.

  conn.py framing PORT SCENE PID   against a daemon with --header-timeout 1 --idle-timeout 8
  conn.py hogs PORT PID            against a daemon with the default limits and timeouts
  conn.py ranges PORT PID          against a daemon with --max-connections 32
                                   --max-connections-per-range 4

Run by tests/http/conn.sh. Raw sockets, since curl and http.client cannot send the
malformed requests. Loopback only: the daemon listens on 127.0.0.1; other clients bind their
sockets to other 127/8 addresses (all local on Linux): 127.0.0.2 is in 127.0.0.1's address
range (127.0.0.0/24), 127.0.1.x and 127.0.2.x are other ranges. Prints "ok - NAME" or
"FAIL - NAME: why" per check. Every wait is bounded, and none is a guess: the daemon's counts
are read from /metrics.
"""
import json
import os
import re
import resource
import socket
import sys
import time

MODE, PORT = sys.argv[1], int(sys.argv[2])
HEALTHZ = b"GET /healthz HTTP/1.1\r\nHost: localhost\r\n\r\n"
SCENE = open(sys.argv[3], "rb").read() if MODE == "framing" else b""
PID = int(sys.argv[4] if MODE == "framing" else sys.argv[3])
results = []


def check(name, ok, why=""):
    results.append(ok)
    print(("ok - " if ok else "FAIL - ") + name + ("" if ok or not why else ": " + why), flush=True)


def connect(src="127.0.0.1", timeout=10.0):
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.bind((src, 0))
    s.settimeout(timeout)
    s.connect(("127.0.0.1", PORT))
    return s


def read_all(s, limit=30.0):
    """Everything until the server closes (or `limit` seconds): the raw answer bytes."""
    out = b""
    end = time.monotonic() + limit
    while time.monotonic() < end:
        try:
            d = s.recv(65536)
        except socket.timeout:
            break
        except ConnectionResetError:
            break
        if not d:
            break
        out += d
    return out


def exchange(raw, src="127.0.0.1"):
    s = connect(src)
    try:
        s.sendall(raw)
    except (BrokenPipeError, ConnectionResetError):
        pass
    out = read_all(s)
    s.close()
    return out


def parse(answer):
    """(status, headers dict lower-case, body, number of status lines) of one answer."""
    head, _, body = answer.partition(b"\r\n\r\n")
    lines = head.decode("latin1").split("\r\n")
    status = int(lines[0].split()[1]) if lines and lines[0].startswith("HTTP/1.") else 0
    hdrs = {}
    for ln in lines[1:]:
        k, _, v = ln.partition(":")
        hdrs[k.strip().lower()] = v.strip()
    return status, hdrs, body, len(re.findall(rb"(?:^|\r\n)HTTP/1\.[01] [0-9]{3} ", answer))


def problem_ok(answer, status):
    """Exactly one answer, with that status, a problem+json body naming the same status."""
    st, h, body, nstatus = parse(answer)
    if nstatus != 1:
        return False, "%d status lines: %r" % (nstatus, answer[:300])
    if st != status:
        return False, "status %d, want %d: %r" % (st, status, answer[:300])
    if not h.get("content-type", "").startswith("application/problem+json"):
        return False, "content-type %r" % h.get("content-type")
    try:
        d = json.loads(body[: int(h.get("content-length", len(body)))])
    except ValueError as e:
        return False, "body not JSON: %s" % e
    if d.get("status") != status or not all(k in d for k in ("type", "title", "detail", "pointer")):
        return False, "problem %r" % d
    return True, ""


def post(headers, body=SCENE):
    return b"POST /v1/render HTTP/1.1\r\n" + headers + b"\r\n" + body


def framing_and_timeouts():
    JSON = b"Content-Type: application/json\r\n"
    LEN = b"Content-Length: %d\r\n" % len(SCENE)

    # ---- framing ----
    a = exchange(b"GET /healthz HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n")
    check("control: GET /healthz 200", parse(a)[0] == 200, repr(a[:200]))
    a = exchange(post(b"Host: localhost\r\nConnection: close\r\n" + JSON + LEN))
    check("control: a valid render 200", parse(a)[0] == 200, repr(a[:200]))

    a = exchange(post(b"Host: localhost\r\n" + JSON + LEN + b"Content-Length: %d\r\n" % (len(SCENE) - 1)))
    check("two different Content-Length headers: 400 problem+json", *problem_ok(a, 400))
    check("two different Content-Length headers: connection closed", parse(a)[1].get("connection") == "close")
    a = exchange(post(b"Host: localhost\r\nConnection: close\r\n" + JSON + LEN + LEN))
    check("two identical Content-Length headers are one value: 200", parse(a)[0] == 200, repr(a[:200]))

    a = exchange(b"GET /healthz HTTP/1.1\r\n\r\n")
    check("HTTP/1.1 without Host: 400 problem+json", *problem_ok(a, 400))
    a = exchange(post(JSON + LEN))
    check("HTTP/1.1 render without Host: 400 problem+json", *problem_ok(a, 400))
    a = exchange(b"GET /healthz HTTP/1.1\r\nHost: a\r\nHost: b\r\n\r\n")
    check("two Host headers: 400 problem+json", *problem_ok(a, 400))
    a = exchange(b"GET /healthz HTTP/1.0\r\n\r\n")
    check("HTTP/1.0 without Host is fine: 200", parse(a)[0] == 200, repr(a[:200]))

    chunked = b"%x\r\n" % len(SCENE) + SCENE + b"\r\n0\r\n\r\n"
    a = exchange(post(b"Host: localhost\r\n" + JSON + b"Transfer-Encoding: chunked\r\nContent-Length: 5\r\n", chunked))
    check("Transfer-Encoding with Content-Length: 400 problem+json", *problem_ok(a, 400))
    a = exchange(post(b"Host: localhost\r\nConnection: close\r\n" + JSON + b"Transfer-Encoding: chunked\r\n", chunked))
    check("control: a chunked render 200", parse(a)[0] == 200, repr(a[:200]))
    a = exchange(post(b"Host: localhost\r\n" + JSON + b"Transfer-Encoding: gzip, chunked\r\n", chunked))
    check("Transfer-Encoding other than chunked: 501 problem+json", *problem_ok(a, 501))

    # The answer to an unparsable Content-Length is libmicrohttpd's own (see README, "Limits of
    # the HTTP layer"); what umbrad guarantees is that the connection ends and others are served.
    a = exchange(post(b"Host: localhost\r\n" + JSON + b"Content-Length: 12x\r\n", b""))
    st = parse(a)[0]
    b = exchange(b"GET /healthz HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n")
    check("invalid Content-Length: 400, closed, the next client served",
          st == 400 and parse(b)[0] == 200, "%r / %r" % (a[:120], b[:120]))

    # ---- every error umbrad answers is problem+json, one status line ----
    errors = [
        (b"GET /nowhere HTTP/1.1\r\nHost: localhost\r\n\r\n", 404),
        (b"DELETE /v1/render HTTP/1.1\r\nHost: localhost\r\n\r\n", 405),
        (b"POST /healthz HTTP/1.1\r\nHost: localhost\r\nContent-Length: 0\r\n\r\n", 405),
        (post(b"Host: localhost\r\nContent-Type: text/plain\r\n" + LEN), 415),
        (post(b"Host: localhost\r\n" + JSON + b"Content-Length: 999999999999\r\n", b""), 413),
        (post(b"Host: localhost\r\n" + JSON + b"Content-Length: 3\r\n", b"{x}"), 400),
        (post(b"Host: localhost\r\n" + JSON + b"X-Priority: urgent\r\n" + LEN), 400),
        (post(b"Host: localhost\r\n" + JSON + b"Content-Length: 0\r\n", b""), 400),
        (b"GET /healthz HTTP/1.1\r\n\r\n", 400),
    ]
    for raw, st in errors:
        ok, why = problem_ok(exchange(raw), st)
        check("%s -> %d problem+json" % (raw.split(b"\r\n")[0].decode(), st), ok, why)

    # ---- timeouts (daemon: --header-timeout 1 --idle-timeout 8) ----
    # A silent connection must go well before the idle timeout would take it.
    s = connect()
    s.settimeout(6)
    try:
        eof = s.recv(1) == b""
    except ConnectionResetError:
        eof = True
    except (socket.timeout, OSError):
        eof = False
    s.close()
    check("a connection that sends nothing is closed by --header-timeout, before --idle-timeout", eof)

    s = connect()
    s.sendall(b"GET /healthz HTTP/1.1\r\nHost: localhost\r\n\r\n")
    first = s.recv(65536)
    time.sleep(3)  # longer than --header-timeout 1, shorter than --idle-timeout 8
    try:
        s.sendall(b"GET /healthz HTTP/1.1\r\nHost: localhost\r\n\r\n")
        second = s.recv(65536)
    except OSError:
        second = b""
    check("keep-alive between requests is governed by --idle-timeout, not --header-timeout",
          parse(first)[0] == 200 and parse(second)[0] == 200, repr(second[:100]))
    t0 = time.monotonic()
    closed = read_all(s, 40.0) == b"" and time.monotonic() - t0 < 40.0
    s.close()
    check("an idle keep-alive connection is closed (--idle-timeout)", closed)

    # A client that goes away in the middle of its body frees its connection at once, not at
    # --idle-timeout (libmicrohttpd's epoll mode missed the end of such a connection).
    fds = lambda: len(os.listdir("/proc/%d/fd" % PID))
    base = fds()
    for _ in range(5):
        s = connect()
        # Corked: the head, half the body and the FIN leave in one segment, so the daemon's
        # first read sees all of it (the case epoll mode missed).
        s.setsockopt(socket.IPPROTO_TCP, socket.TCP_CORK, 1)
        s.sendall(post(b"Host: localhost\r\n" + JSON + LEN, SCENE[: len(SCENE) // 2]))
        s.close()
    for _ in range(40):
        if fds() <= base:
            break
        time.sleep(0.1)
    check("5 connections closed mid-body are released before --idle-timeout (%d -> %d fds)" % (base, fds()),
          fds() <= base)

def hogs(pid):
    """1024 idle sockets from 127.0.0.1 against a daemon with the default limits."""
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    resource.setrlimit(resource.RLIMIT_NOFILE, (max(soft, min(hard, 4096)), hard))

    def fds():
        return len(os.listdir("/proc/%d/fd" % pid))

    base = fds()
    held = []
    for i in range(1024):
        try:
            held.append(connect("127.0.0.1", timeout=5))
        except OSError:
            break
    # connect() returns once the kernel has the connection; wait (bounded) until the daemon has
    # taken what it will take from the listen queue.
    last, still = -1, 0
    for _ in range(100):
        n = fds()
        still = still + 1 if n == last else 0
        if still >= 5:
            break
        last = n
        time.sleep(0.1)
    held_by_daemon = fds() - base
    check("the daemon holds at most 256 connections from one address (%d held)" % held_by_daemon,
          held_by_daemon <= 256 + 2)
    # Over the per-address limit the library accepts and closes at once (no answer).
    extra = connect("127.0.0.1", timeout=5)
    extra.settimeout(5)
    try:
        extra.sendall(b"GET /healthz HTTP/1.1\r\nHost: localhost\r\n\r\n")
        got = extra.recv(65536)
        eof = got == b""
    except ConnectionResetError:
        got, eof = b"", True
    except (socket.timeout, OSError):
        got, eof = b"", False
    extra.close()
    check("over --max-connections-per-ip: the connection is closed at once, unanswered", eof, repr(got[:100]))
    # The other client must be answered while the 1024 sockets are still open and idle (well
    # within --header-timeout 10).
    try:
        s = connect("127.0.1.2", timeout=5)
        s.sendall(b"GET /healthz HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n")
        other = read_all(s, 5.0)
        s.close()
    except OSError as e:
        other = repr(e).encode()
    check("1024 idle sockets from 127.0.0.1 do not shut out 127.0.1.2 (another address range)",
          parse(other)[0] == 200, repr(other[:100]))
    # 127.0.0.1's 256 are the share of its range, 127.0.0.0/24 (a quarter of 1024).
    check("... while 127.0.0.2 (the same /24, at its share) is closed at accept, unanswered",
          refused("127.0.0.2"), "it was answered")
    for h in held:
        h.close()


def read_answer(s, limit=10.0):
    """One answer on a kept-alive connection (head and Content-Length body), b"" at EOF."""
    out = b""
    end = time.monotonic() + limit
    while time.monotonic() < end:
        head, sep, body = out.partition(b"\r\n\r\n")
        if sep:
            m = re.search(rb"(?i)\r\ncontent-length: *([0-9]+)", head)
            if len(body) >= (int(m.group(1)) if m else 0):
                return out
        try:
            d = s.recv(65536)
        except (socket.timeout, ConnectionResetError):
            break
        if not d:
            break
        out += d
    return out


def refused(src):
    """A connection from src is closed at once without an answer."""
    s = connect(src, timeout=5)
    try:
        s.sendall(HEALTHZ)
        got = s.recv(65536)
    except ConnectionResetError:
        got = b""
    except (socket.timeout, OSError):
        got = b"(no close)"
    s.close()
    return got == b""


def metrics(src):
    """The daemon's /metrics as {series: value}, asked from src."""
    a = exchange(b"GET /metrics HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n", src)
    out = {}
    for ln in parse(a)[2].decode("utf-8", "replace").split("\n"):
        if ln and not ln.startswith("#"):
            k, _, v = ln.rpartition(" ")
            out[k] = float(v)
    return out


def ranges():
    """Share per address range 4 (IPv4 /24) of --max-connections 32: one range at its share is
    refused at accept while another is served, the refusal is counted, a freed place is reused."""
    REFUSED = 'umbra_connections_refused_total{reason="range_share"}'
    held = []
    answers = []
    # Two addresses of 127.0.1.0/24, two kept-alive connections each: 4 = the range's share.
    # Each is answered once, so the daemon has counted it before the next step.
    for src in ("127.0.1.2", "127.0.1.2", "127.0.1.3", "127.0.1.3"):
        s = connect(src)
        s.sendall(HEALTHZ)
        answers.append(parse(read_answer(s))[0])
        held.append(s)
    check("4 kept-alive connections from 127.0.1.2 and 127.0.1.3 answered 200", answers == [200] * 4, repr(answers))
    m0 = metrics("127.0.3.2")
    check("/metrics: the share is 4", m0.get("umbra_connections_per_range_limit") == 4,
          repr(m0.get("umbra_connections_per_range_limit")))
    check("a fifth connection from the range (127.0.1.4, a third address) is closed at accept, unanswered",
          refused("127.0.1.4"), "it was answered")
    a = exchange(b"GET /healthz HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n", "127.0.2.2")
    check("another range (127.0.2.2) is served while 127.0.1.0/24 is at its share", parse(a)[0] == 200, repr(a[:100]))
    m1 = metrics("127.0.3.2")
    check("/metrics: exactly that one refusal counted (reason range_share)",
          m1.get(REFUSED, -1) - m0.get(REFUSED, 0) == 1, "%r -> %r" % (m0.get(REFUSED), m1.get(REFUSED)))
    check("/metrics: the held connections are open (and counted in ranges)",
          m1.get("umbra_connections_open", 0) >= 5 and m1.get("umbra_connection_ranges", 0) >= 2,
          "open %r ranges %r" % (m1.get("umbra_connections_open"), m1.get("umbra_connection_ranges")))
    # One of the range's connections closes: once the daemon has let it go (3 held + the scrape
    # itself; a scrape just answered may still be counted for a moment), the range fits again.
    held.pop().close()
    m = {}
    for _ in range(100):
        m = metrics("127.0.3.2")
        if m.get("umbra_connections_open", 99) <= len(held) + 1:
            break
        time.sleep(0.1)
    check("the daemon lets the closed connection go (umbra_connections_open %r)" % m.get("umbra_connections_open"),
          m.get("umbra_connections_open", 99) <= len(held) + 1)
    a = exchange(b"GET /healthz HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n", "127.0.1.4")
    check("a freed place in the share serves the range again (127.0.1.4)", parse(a)[0] == 200, repr(a[:100]))
    m2 = metrics("127.0.3.2")
    check("/metrics: no further refusal", m2.get(REFUSED, -1) == m1.get(REFUSED), repr(m2.get(REFUSED)))
    for h in held:
        h.close()


if sys.argv[1] == "hogs":
    hogs(PID)
elif sys.argv[1] == "ranges":
    ranges()
else:
    framing_and_timeouts()
print("%d passed, %d failed" % (results.count(True), results.count(False)))
sys.exit(0 if all(results) else 1)
