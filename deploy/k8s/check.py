#!/usr/bin/env python3
"""deploy/k8s/check.py — what can be checked of the manifests without a cluster.

    python3 deploy/k8s/check.py [DIR]          (make check-deploy)

Python 3 with Debian's python3-yaml only. Not a schema validation (that is validate.mjs, with
the npm package kubernetes-models): this checks that every document parses, carries the fields
its kind requires, and that the pieces agree with each other and with umbrad:
  - apiVersion/kind/metadata.name on every document; kinds are the ones expected here;
  - Deployment: selector matches the pod labels; a versioned image; readiness and start-up on
    /readyz, liveness on /healthz, on
    the container's named port; preStop present; terminationGracePeriodSeconds longer than
    preStop + UMBRA_DRAIN_TIMEOUT (from the ConfigMap) and than the deadline; CPU/memory
    requests and limits; read-only root filesystem, non-root user, no privilege escalation;
    every mounted volume declared; envFrom names a ConfigMap that exists;
  - ConfigMap: every key is a umbrad variable (UMBRA_ + a flag from `umbrad --help`) or a
    variable the container needs; values are strings;
  - Service and PodDisruptionBudget selectors match the pods; Service targetPort names a
    container port; HPAs target the Deployment and have min <= max;
  - Job (the farm, farm-job.yaml): Indexed, its completions = the N of `--shard
    $JOB_COMPLETION_INDEX/N`, --resume, --server naming a Service here on its port, the same
    security settings as the Deployment, every mounted volume declared;
  - kustomization.yaml lists files that exist.
Prints "ok - x" / "FAIL - x" and "N passed, N failed"; exit 1 on a failure.
"""
import glob
import os
import re
import subprocess
import sys

import yaml

passed = failed = 0


def check(name, cond, detail=""):
    global passed, failed
    if cond:
        passed += 1
        print("ok - %s" % name)
    else:
        failed += 1
        print("FAIL - %s%s" % (name, ": " + str(detail) if detail else ""))


def get(d, path, default=None):
    for p in path.split("."):
        if isinstance(d, list):
            d = d[int(p)] if p.isdigit() and int(p) < len(d) else None
        elif isinstance(d, dict):
            d = d.get(p)
        else:
            d = None
        if d is None:
            return default
    return d


def umbrad_flags(build):
    """Flags from `umbrad --help` as UMBRA_ variables; None when umbrad is not built."""
    exe = os.path.join(build, "umbrad")
    if not os.access(exe, os.X_OK):
        return None
    out = subprocess.run([exe, "--help"], capture_output=True, text=True, timeout=30).stdout
    return {"UMBRA_" + f.upper().replace("-", "_") for f in re.findall(r"--([a-z][a-z-]+) ", out)}


def selector_matches(sel, labels):
    return bool(sel) and all(labels.get(k) == v for k, v in sel.items())


def check_deployment(f, d, cms):
    name = "%s Deployment/%s" % (f, get(d, "metadata.name"))
    spec, pod = d.get("spec", {}), get(d, "spec.template.spec", {})
    labels = get(d, "spec.template.metadata.labels", {})
    check(name + ": selector matches pod labels", selector_matches(get(spec, "selector.matchLabels"), labels))
    cs = pod.get("containers") or []
    check(name + ": has containers with name and image", cs and all(c.get("name") and c.get("image") for c in cs))
    c = cs[0] if cs else {}
    ports = {p.get("name"): p.get("containerPort") for p in c.get("ports", [])}
    img = c.get("image", "")
    check(name + ": image has a version tag, not :latest", ":" in img.rsplit("/", 1)[-1] and not img.endswith(":latest"), img)
    # The startup probe waits for the warm-up: /readyz (a /healthz one passes before it).
    for probe, path in (("readinessProbe", "/readyz"), ("livenessProbe", "/healthz"), ("startupProbe", "/readyz")):
        hg = get(c, probe + ".httpGet", {})
        check("%s: %s on %s" % (name, probe, path), hg.get("path") == path and hg.get("port") in ports, hg)
    pre = get(c, "lifecycle.preStop.exec.command") or []
    pre_s = int(pre[1]) if len(pre) == 2 and pre[0] == "sleep" and str(pre[1]).isdigit() else None
    check(name + ": preStop sleep", pre_s is not None, pre)
    env = {}
    for ref in c.get("envFrom", []):
        cm = get(ref, "configMapRef.name")
        check(name + ": envFrom ConfigMap %s exists" % cm, cm in cms)
        env.update(cms.get(cm, {}))
    grace = pod.get("terminationGracePeriodSeconds", 30)
    drain = int(env.get("UMBRA_DRAIN_TIMEOUT", 60))
    deadline_s = int(env.get("UMBRA_DEADLINE_MS", 30000)) / 1000.0
    check(name + ": grace %ss > preStop %ss + drain %ss" % (grace, pre_s, drain), grace > (pre_s or 0) + drain)
    check(name + ": grace %ss > deadline %.0fs" % (grace, deadline_s), grace > deadline_s)
    check(name + ": drain %ss >= deadline %.0fs" % (drain, deadline_s), drain >= deadline_s)
    for kind in ("requests", "limits"):
        r = get(c, "resources." + kind, {})
        check("%s: resources.%s cpu and memory" % (name, kind), "cpu" in r and "memory" in r, r)
    sc, psc = c.get("securityContext", {}), pod.get("securityContext", {})
    check(name + ": readOnlyRootFilesystem", sc.get("readOnlyRootFilesystem") is True)
    check(name + ": allowPrivilegeEscalation false", sc.get("allowPrivilegeEscalation") is False)
    check(name + ": capabilities drop ALL", "ALL" in (get(sc, "capabilities.drop") or []))
    non_root = (sc.get("runAsNonRoot") or psc.get("runAsNonRoot")) and \
        int(sc.get("runAsUser", psc.get("runAsUser", 0))) != 0
    check(name + ": non-root user", bool(non_root))
    vols = {v.get("name") for v in pod.get("volumes", [])}
    mounts = [m.get("name") for m in c.get("volumeMounts", [])]
    check(name + ": every mount has a volume", all(m in vols for m in mounts), mounts)
    check(name + ": writable cache and /tmp mounted (read-only root)",
          {"/tmp", "/var/cache/umbra"} <= {m.get("mountPath") for m in c.get("volumeMounts", [])})
    return labels, ports


def check_job(f, d, services):
    """The farm's Indexed Job: shards, resume, a Service it can reach, a locked-down pod."""
    name = "%s Job/%s" % (f, get(d, "metadata.name"))
    spec, pod = d.get("spec", {}), get(d, "spec.template.spec", {})
    c = (pod.get("containers") or [{}])[0]
    cmd = " ".join(str(x) for x in (c.get("command") or []) + (c.get("args") or []))
    check(name + ": completionMode Indexed", spec.get("completionMode") == "Indexed")
    m = re.search(r"--shard \"?\$\(?JOB_COMPLETION_INDEX\)?/(\d+)", cmd)
    check(name + ": --shard $JOB_COMPLETION_INDEX/N with N = completions %s" % spec.get("completions"),
          m and int(m.group(1)) == spec.get("completions"), m and m.group(0))
    check(name + ": parallelism <= completions", spec.get("parallelism", 1) <= spec.get("completions", 0))
    check(name + ": runs umbra-render thumb --resume", "umbra-render thumb" in cmd and "--resume" in cmd, cmd)
    srv = re.search(r"--server http://([a-z0-9-]+)(?::(\d+))?", cmd)
    port = int(srv.group(2) or 80) if srv else None
    ok_srv = srv and srv.group(1) in services and port in services[srv.group(1)]
    check(name + ": --server names a Service here on one of its ports", ok_srv, srv and srv.group(0))
    check(name + ": restartPolicy Never or OnFailure", pod.get("restartPolicy") in ("Never", "OnFailure"))
    sc, psc = c.get("securityContext", {}), pod.get("securityContext", {})
    check(name + ": readOnlyRootFilesystem, no privilege escalation, capabilities drop ALL",
          sc.get("readOnlyRootFilesystem") is True and sc.get("allowPrivilegeEscalation") is False and
          "ALL" in (get(sc, "capabilities.drop") or []))
    check(name + ": non-root user", bool(psc.get("runAsNonRoot")) and int(psc.get("runAsUser", 0)) != 0)
    for kind in ("requests", "limits"):
        r = get(c, "resources." + kind, {})
        check("%s: resources.%s cpu and memory" % (name, kind), "cpu" in r and "memory" in r, r)
    vols = {v.get("name") for v in pod.get("volumes", [])}
    mounts = [mt.get("name") for mt in c.get("volumeMounts", [])]
    check(name + ": every mount has a volume", all(mt in vols for mt in mounts), mounts)


def main(argv):
    root = argv[0] if argv else os.path.dirname(os.path.abspath(__file__))
    build = os.environ.get("BUILD", "build")
    docs = []
    for f in sorted(glob.glob(os.path.join(root, "*.yaml"))):
        try:
            with open(f) as fh:
                for d in yaml.safe_load_all(fh):
                    if d is not None:
                        docs.append((os.path.basename(f), d))
            check("%s parses" % os.path.basename(f), True)
        except yaml.YAMLError as e:
            check("%s parses" % os.path.basename(f), False, e)
    required = {"ConfigMap": ["data"], "Deployment": ["spec.selector", "spec.template.spec.containers"],
                "Service": ["spec.ports", "spec.selector"], "PodDisruptionBudget": ["spec.selector"],
                "HorizontalPodAutoscaler": ["spec.scaleTargetRef", "spec.maxReplicas", "spec.metrics"],
                "Kustomization": ["resources"], "Job": ["spec.completions", "spec.template.spec.containers"]}
    for f, d in docs:
        kind = d.get("kind")
        fields = ["apiVersion", "kind"] + ([] if kind == "Kustomization" else ["metadata.name"])
        fields += required.get(kind, [])
        missing = [p for p in fields if get(d, p) is None]
        check("%s %s: required fields" % (f, kind), kind in required and not missing, missing or kind)
    cms = {get(d, "metadata.name"): d.get("data", {}) for f, d in docs if d.get("kind") == "ConfigMap"}
    known = umbrad_flags(build)
    for name, data in cms.items():
        check("ConfigMap %s: values are strings" % name, all(isinstance(v, str) for v in data.values()))
        if known is not None:
            unknown = [k for k in data if k not in known]
            check("ConfigMap %s: every key is a umbrad flag" % name, not unknown, unknown)
    deps = {}
    for f, d in docs:
        if d.get("kind") == "Deployment":
            deps[get(d, "metadata.name")] = check_deployment(f, d, cms)
    services = {get(d, "metadata.name"): {p.get("port") for p in get(d, "spec.ports", [])}
                for f, d in docs if d.get("kind") == "Service"}
    jobs = [(f, d) for f, d in docs if d.get("kind") == "Job"]
    check("a farm Job is here (farm-job.yaml)", bool(jobs))
    for f, d in jobs:
        check_job(f, d, services)
    for f, d in docs:
        kind, name = d.get("kind"), "%s %s/%s" % (f, d.get("kind"), get(d, "metadata.name"))
        if kind == "Service":
            sel = get(d, "spec.selector", {})
            hit = [dn for dn, (labels, _) in deps.items() if selector_matches(sel, labels)]
            check(name + ": selects the pods", bool(hit))
            ports = deps[hit[0]][1] if hit else {}
            tps = [p.get("targetPort") for p in get(d, "spec.ports", [])]
            check(name + ": targetPort is a container port", all(t in ports or t in ports.values() for t in tps), tps)
        elif kind == "PodDisruptionBudget":
            sel = get(d, "spec.selector.matchLabels", {})
            check(name + ": selects the pods", any(selector_matches(sel, lb) for lb, _ in deps.values()))
        elif kind == "HorizontalPodAutoscaler":
            ref = get(d, "spec.scaleTargetRef", {})
            check(name + ": targets a Deployment here", ref.get("kind") == "Deployment" and ref.get("name") in deps)
            check(name + ": minReplicas <= maxReplicas",
                  get(d, "spec.minReplicas", 1) <= get(d, "spec.maxReplicas", 0))
        elif kind == "Kustomization":
            res = d.get("resources", [])
            check(name + ": resources exist", all(os.path.exists(os.path.join(root, r)) for r in res), res)
    print("%d passed, %d failed" % (passed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
