#!/usr/bin/env python3
"""tests/http/check_metrics.py FILE — checks a /metrics answer against the Prometheus text
format 0.0.4 the way `promtool check metrics` would reject it (the suites use promtool itself
when it is installed; this is the check when it is not):

  - every line is a `# HELP name text`, a `# TYPE name counter|gauge|histogram|...`, or a
    sample `name{label="value",...} number` with legal names and escaped label values;
  - one TYPE per family, before its first sample, and no family's samples split by another's;
  - no series twice; a counter's name ends in _total; a histogram has _bucket series with le
    (cumulative, ending in +Inf equal to its _count) and _sum and _count per label set.

Exit 0 when clean, else 1 with one line per problem (at most 20).
"""
import math
import re
import sys

NAME = r"[a-zA-Z_:][a-zA-Z0-9_:]*"
LABEL = r'[a-zA-Z_][a-zA-Z0-9_]*="(?:[^"\\\n]|\\["\\n])*"'
SAMPLE = re.compile(r"^(%s)(?:\{((?:%s)(?:,%s)*)?\})? (\S+)$" % (NAME, LABEL, LABEL))
PAIR = re.compile(r'([a-zA-Z_][a-zA-Z0-9_]*)="((?:[^"\\\n]|\\["\\n])*)"')
TYPES = {"counter", "gauge", "histogram", "summary", "untyped"}


def family_of(name, types):
    for suffix in ("_bucket", "_sum", "_count"):
        if name.endswith(suffix) and types.get(name[: -len(suffix)]) == "histogram":
            return name[: -len(suffix)]
    return name


def main(path):
    problems = []
    types, seen, done = {}, set(), set()
    hist = {}   # (family, labels without le) -> {"buckets": [(le, v)], "count": v, "sum": v}
    current = None
    for n, line in enumerate(open(path, encoding="utf-8").read().split("\n"), 1):
        if not line:
            continue
        if line.startswith("#"):
            parts = line.split(" ", 3)
            if len(parts) >= 3 and parts[1] == "TYPE":
                if parts[2] in types:
                    problems.append("line %d: second TYPE for %s" % (n, parts[2]))
                if len(parts) < 4 or parts[3] not in TYPES:
                    problems.append("line %d: bad TYPE line %r" % (n, line))
                types[parts[2]] = parts[3] if len(parts) > 3 else ""
                if parts[3:] == ["counter"] and not parts[2].endswith("_total"):
                    problems.append("line %d: counter %s does not end in _total" % (n, parts[2]))
            elif len(parts) >= 3 and parts[1] == "HELP":
                if not re.fullmatch(NAME, parts[2]):
                    problems.append("line %d: bad HELP name %r" % (n, parts[2]))
            continue
        m = SAMPLE.match(line)
        if not m:
            problems.append("line %d: not a sample: %r" % (n, line))
            continue
        name, labels, value = m.group(1), m.group(2) or "", m.group(3)
        try:
            v = float(value)
        except ValueError:
            problems.append("line %d: bad value %r" % (n, value))
            continue
        fam = family_of(name, types)
        if fam not in types:
            problems.append("line %d: %s has no TYPE before it" % (n, name))
        if fam != current:
            if fam in done:
                problems.append("line %d: samples of %s are not together" % (n, fam))
            if current:
                done.add(current)
            current = fam
        key = (name, labels)
        if key in seen:
            problems.append("line %d: series twice: %s{%s}" % (n, name, labels))
        seen.add(key)
        if types.get(fam) == "histogram":
            pairs = [p for p in PAIR.findall(labels) if p[0] != "le"]
            h = hist.setdefault((fam, tuple(pairs)), {"buckets": [], "count": None, "sum": None})
            if name.endswith("_bucket"):
                le = dict(PAIR.findall(labels)).get("le")
                if le is None:
                    problems.append("line %d: bucket without le" % n)
                else:
                    h["buckets"].append((float(le), v))
            elif name.endswith("_count"):
                h["count"] = v
            elif name.endswith("_sum"):
                h["sum"] = v
    for (fam, pairs), h in hist.items():
        what = "%s%s" % (fam, dict(pairs) or "")
        b = h["buckets"]
        if not b or not math.isinf(b[-1][0]):
            problems.append("%s: no +Inf bucket" % what)
            continue
        if any(b[i][0] >= b[i + 1][0] or b[i][1] > b[i + 1][1] for i in range(len(b) - 1)):
            problems.append("%s: buckets not increasing" % what)
        if h["count"] != b[-1][1] or h["sum"] is None:
            problems.append("%s: _count %s != +Inf bucket %s, or no _sum" % (what, h["count"], b[-1][1]))
    for p in problems[:20]:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
