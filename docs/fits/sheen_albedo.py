#!/usr/bin/env python3
"""docs/fits/sheen_albedo.py — where the constants of ext_sheen_albedo() (shaders/material_ext.glsl)
come from: the directional albedo E(mu, r) of the sheen lobe umbra draws (the Charlie distribution
times the sample viewer's sheen visibility, white, times N.L), integrated over the hemisphere on a
grid of mu = N.V and roughness r, capped at 1, then fitted as exp(c0 + c1 mu + c2 mu^2) with each
c cubic in r (least squares in log space, weighted by E). Prints the coefficients and the error.
Needs numpy (Debian python3-numpy); not run by the build."""
import numpy as np


def lam_fit(x, ag):
    t = (1 - ag) ** 2
    a = 21.5473 * (1 - t) + 25.3245 * t
    b = 3.82987 * (1 - t) + 3.32435 * t
    c = 0.19823 * (1 - t) + 0.16801 * t
    d = -1.97760 * (1 - t) - 1.27393 * t
    e = -4.32054 * (1 - t) - 4.85967 * t
    return a / (1 + b * np.power(x, c)) + d * x + e


def lam(ct, ag):
    return np.where(np.abs(ct) < 0.5, np.exp(lam_fit(ct, ag)), np.exp(2 * lam_fit(0.5, ag) - lam_fit(1 - ct, ag)))


def albedo(mu, r, n=256):
    ag = max(r, 1e-3) ** 2
    th = (np.arange(n) + 0.5) / n * np.pi / 2
    ph = (np.arange(2 * n) + 0.5) / (2 * n) * 2 * np.pi
    T, P = np.meshgrid(th, ph, indexing="ij")
    l = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1)
    v = np.array([np.sqrt(1 - mu * mu), 0, mu])
    h = l + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    nl, nh = l[..., 2], h[..., 2]
    inv = 1 / ag
    D = (2 + inv) * np.power(np.maximum(1 - nh * nh, 0), inv * 0.5) / (2 * np.pi)
    V = np.clip(1 / ((1 + lam(mu, ag) + lam(nl, ag)) * (4 * mu * nl)), 0, 1)
    dA = np.sin(T) * (np.pi / 2 / n) * (2 * np.pi / (2 * n))
    return float((D * V * nl * dA).sum())


def main():
    mus, rs = np.linspace(0.02, 1, 25), np.linspace(0.05, 1, 20)
    tab = np.minimum(np.array([[albedo(m, r) for m in mus] for r in rs]), 1.0)
    M, R = np.meshgrid(mus, rs)
    mu, r = M.ravel(), R.ravel()
    X = np.stack([r ** k * mu ** j for k in range(4) for j in range(3)], -1)
    w = np.sqrt(np.maximum(tab.ravel(), 1e-3))
    coef, *_ = np.linalg.lstsq(X * w[:, None], np.log(np.maximum(tab.ravel(), 1e-4)) * w, rcond=None)
    err = np.abs(np.exp(X @ coef).reshape(tab.shape) - tab)
    c = coef.reshape(4, 3)
    for j in range(3):
        print("c%d = dot(rk, vec4(%s))" % (j, ", ".join("%.4f" % x for x in c[:, j])))
    print("max error %.3f, %.3f for r >= 0.2, mean %.4f" % (err.max(), err[rs >= 0.2].max(), err.mean()))


if __name__ == "__main__":
    main()
