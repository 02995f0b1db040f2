#!/usr/bin/env python3
"""tests/sizes.py [--functions N] [--files N] [DIR...] — the house style's sizes (GUIDE.md: files
under ~600 lines, functions under ~80): lists every file of DIRs (default api renderer server)
longer than --files lines (600) and every function longer than --functions lines (80), longest
first, as `lines  path:line  name`; with the default DIRs, also the test sources (tests/: C,
Python, shell, JavaScript) longer than --files lines (their files only: a test's body may run
long). A list to read, not a test: it always exits 0 (`make sizes`).

A C function is what the house style writes: its signature from column 0, its body from a `{`
alone on a line at column 0 to the `}` at column 0 that closes it; its length counts the
signature's lines too. A JavaScript function is a `function NAME(` or `async function NAME(`
line at column 0 to the next `}` at column 0.
"""
import os
import re
import sys

SOURCES = (".c", ".h", ".cpp", ".js", ".css", ".html")
TEST_SOURCES = (".c", ".h", ".cpp", ".js", ".py", ".sh")
C_SOURCES = (".c", ".cpp")
NAME = re.compile(r"([A-Za-z_]\w*)\s*\(")


def closing(lines, i):
    """The index of the first line after i that starts with `}` (a body's end at column 0)."""
    end = i + 1
    while end < len(lines) and not lines[end].startswith("}"):
        end += 1
    return end


def c_functions(lines):
    """(first line, length, name) of each function definition in a C file."""
    out = []
    for i, l in enumerate(lines):
        if l.rstrip() != "{" or i == 0:
            continue
        start = i - 1
        # the signature: back to its first line (the one at column 0 that is no continuation)
        while start > 0 and lines[start - 1].strip() and (lines[start][:1] in (" ", "\t") or
                                                          not lines[start - 1].rstrip().endswith((";", "}", "*/"))):
            if lines[start - 1].startswith(("#", "/*", " *", "//")):
                break
            start -= 1
        m = NAME.search(lines[start])
        if not m or lines[start].startswith(("struct ", "enum ", "union ")) and "(" not in lines[start]:
            continue
        out.append((start + 1, closing(lines, i) - start + 1, m.group(1)))
    return out


def js_functions(lines):
    out = []
    for i, l in enumerate(lines):
        m = re.match(r"(?:async\s+)?function\s+(\w+)\s*\(", l)
        if not m or l.rstrip().endswith("}"):
            continue
        out.append((i + 1, closing(lines, i) - i + 1, m.group(1)))
    return out


def sources(d, exts):
    """(path, lines) of each file under d whose name ends in one of exts (node_modules skipped)."""
    for root, subdirs, names in os.walk(d):
        subdirs[:] = sorted(s for s in subdirs if s != "node_modules")
        for n in sorted(names):
            if not n.endswith(exts):
                continue
            p = os.path.join(root, n)
            with open(p, encoding="utf-8", errors="replace") as f:
                lines = f.read().split("\n")
            if lines and lines[-1] == "":
                lines.pop()
            yield p, lines


def main(argv):
    fmax, lmax, dirs = 80, 600, []
    it = iter(argv)
    for a in it:
        if a == "--functions":
            fmax = int(next(it))
        elif a == "--files":
            lmax = int(next(it))
        else:
            dirs.append(a)
    files, funcs = [], []
    for d in dirs or ["api", "renderer", "server"]:
        for p, lines in sources(d, SOURCES):
            if len(lines) > lmax:
                files.append((len(lines), p))
            found = c_functions(lines) if p.endswith(C_SOURCES) else js_functions(lines) if p.endswith(".js") else []
            funcs += [(length, "%s:%d" % (p, first), name) for first, length, name in found if length > fmax]
    tests = [] if dirs else [(len(lines), p) for p, lines in sources("tests", TEST_SOURCES) if len(lines) > lmax]
    print("# files over %d lines: %d" % (lmax, len(files)))
    for n, p in sorted(files, reverse=True):
        print("%5d  %s" % (n, p))
    if not dirs:
        print("# test files over %d lines: %d" % (lmax, len(tests)))
        for n, p in sorted(tests, reverse=True):
            print("%5d  %s" % (n, p))
    print("# functions over %d lines: %d" % (fmax, len(funcs)))
    for n, where, name in sorted(funcs, reverse=True):
        print("%5d  %s  %s" % (n, where, name))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
