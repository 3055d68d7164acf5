#!/usr/bin/env python3
"""A far-field step set by the field's slow scale: a prototype, measured (docs/measurements.md, "Limits, measured").

The lead of the far field's resonances (bench/far_field.py): a step that does not kick but integrates the
force's action along the exact helix, sampling the force only along the slow path of the guiding centre
G = R + K1 x K2/|K1|^2. This prototype builds it numerically, to learn what such a step can achieve before
its closed-form version is written in C++:

* Interaction picture. Phi_t is the exact kinetic drift (docs/physics.md, "Exact Lie-Poisson splitting");
  the state is x(t) = Phi_t(y(t)) with y' = DPhi_{-t}(x(t)) P(x(t)), P = (0, F(R), 0) the kick's field. y
  changes by the force only: slowly, with ripples of the spin period.
* The force along the helix from field data at the guiding centre's path: at q + 1 Chebyshev nodes of the
  step the Coulomb field's Taylor tensors up to order 3 are evaluated at G (one *field evaluation* per
  node: F and its first three derivatives at one point), interpolated in t, and F(R(t)) is their Taylor
  sum at xi = R(t) - G(t) (|xi| = rho, so the truncation is (rho/r)^4 relative).
* The step's integral: Picard iteration of y on a Chebyshev grid fine enough for the spin (a few points
  per radian: arithmetic, no force evaluations), the pulled-back field by a complex-step derivative of
  Phi_{-t}, until y stops changing. By default the field is evaluated in the first iteration only, on the
  unperturbed helix's guiding-centre path; later iterations move the path by far less than rho and keep
  those nodes (the Taylor sum reaches the new path from them). --field-iterations K evaluates it in the
  first K iterations instead.

It prints, on the far pass of bench/far_field.py (the thesis scene with Kz = 0.1, d = 50, t = 80; rho = 0.02
and r >= 50) and on the same pass with the thesis's Kz = 5 (rho = 1), the error against odeint-rkf78 at tol
1e-15 for steps of 0.5 to 100 rad of spin, with the field evaluations, their number per radian of spin and
the Picard iterations per step, and the measured order between successive steps.

Usage (from the repository, after the build):
    PYTHONPATH=build/python /usr/bin/python3 bench/far_field_gc.py [--nodes Q] [--out CSV]
"""
import argparse
import math

import numpy as np
import bodypoint as bp

# The far passes, their reference, error measure and CSV writing are far_field.py's (the same folder).
from far_field import B, J, K1 as K1_0, M, SPIN_RATE, T_END, distance, write_csv

D = M * J - B * B
S = B / D                       # K2 turns about K1 at the rate S |K1|
ANGLES = [0.5, 1.0, 2.0, 3.14, 5.0, 6.28, 10.0, 12.57, 20.0, 30.0, 40.0, 55.0, 70.0, 100.0]
CENTRES = [(np.zeros(3), -2.0)]  # the thesis scene's centre: A = -2 at the origin
PICARD_TOL = 1e-15               # y is converged when an iteration changes it by less (relative)
MAX_PICARD = 12                  # a step that needs more is reported as not converged
COMPLEX_STEP = 1e-30             # the complex-step derivative's increment (exact to rounding at any size)
# Chebyshev points per radian of spin on the step's fine grid (arithmetic only: no force evaluations).
# 1.5 and 3 give errors within 12 % of each other at every step of ANGLES on both passes; 1 errs up to
# 1.8x more from 19.6 rad per step on (measured).
FINE_PER_RADIAN = 1.5
MIN_FINE = 24


def cross(a, b):
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def dot(a, b):
    return np.sum(a * b, axis=-1)


def drift(R, K1, K2, tau):
    """The exact kinetic drift for times tau (arrays over a leading axis; complex-capable: no conj, no abs)."""
    k = np.sqrt(dot(K1, K1))
    u = K1 / k[..., None]
    theta = -S * k * tau
    c, s = np.cos(theta)[..., None], np.sin(theta)[..., None]
    K2n = K2 * c + cross(u, K2) * s + u * dot(u, K2)[..., None] * (1.0 - c)
    k2 = (k * k)[..., None]
    Rn = R + tau[..., None] * (J * K1 - B * dot(u, K2)[..., None] * u) / D + cross(K1, K2 - K2n) / k2
    return Rn, K1, K2n


def guiding_centre(R, K1, K2):
    return R + cross(K1, K2) / dot(K1, K1)[..., None]


def field_taylor(g):
    """F and its derivatives of order 1-3 at the points g (n, 3), summed over the centres."""
    n = g.shape[0]
    I = np.eye(3)
    T0, T1, T2, T3 = np.zeros((n, 3)), np.zeros((n, 3, 3)), np.zeros((n, 3, 3, 3)), np.zeros((n, 3, 3, 3, 3))
    for c, A in CENTRES:
        x = g - c
        r2 = dot(x, x)
        r = np.sqrt(r2)
        r3, r5, r7, r9 = r ** 3, r ** 5, r ** 7, r ** 9
        T0 += -A * x / r3[:, None]
        xx = np.einsum("ni,nj->nij", x, x)
        T1 += -A * (I[None] / r3[:, None, None] - 3.0 * xx / r5[:, None, None])
        xxx = np.einsum("nij,nk->nijk", xx, x)
        dx = (np.einsum("ij,nk->nijk", I, x) + np.einsum("ik,nj->nijk", I, x) + np.einsum("jk,ni->nijk", I, x))
        T2 += -A * (-3.0 * dx / r5[:, None, None, None] + 15.0 * xxx / r7[:, None, None, None])
        dd = np.einsum("ij,kl->ijkl", I, I) + np.einsum("ik,jl->ijkl", I, I) + np.einsum("jk,il->ijkl", I, I)
        dxx = (np.einsum("ij,nkl->nijkl", I, xx) + np.einsum("ik,njl->nijkl", I, xx) +
               np.einsum("jk,nil->nijkl", I, xx) + np.einsum("il,njk->nijkl", I, xx) +
               np.einsum("jl,nik->nijkl", I, xx) + np.einsum("kl,nij->nijkl", I, xx))
        xxxx = np.einsum("nijk,nl->nijkl", xxx, x)
        T3 += -A * (-3.0 * dd[None] / r5[:, None, None, None, None] + 15.0 * dxx / r7[:, None, None, None, None]
                    - 105.0 * xxxx / r9[:, None, None, None, None])
    return T0, T1, T2, T3


def chebyshev_grid(n):
    """Chebyshev-Lobatto points of [0, 1] (n + 1 of them) and the matrix of the cumulative integral from 0."""
    x = -np.cos(np.pi * np.arange(n + 1) / n)           # [-1, 1], increasing
    V = np.polynomial.chebyshev.chebvander(x, n)
    C = np.linalg.inv(V)                                 # values -> coefficients
    Vi = np.stack([np.polynomial.chebyshev.chebval(x, np.polynomial.chebyshev.chebint(np.eye(n + 1)[j], lbnd=-1))
                   for j in range(n + 1)], axis=1)       # coefficient j -> integral from -1 at the points
    return (x + 1.0) / 2.0, Vi @ C / 2.0


def lagrange_matrix(nodes, points):
    """Values at `nodes` -> the interpolating polynomial's values at `points` (barycentric form)."""
    w = np.array([1.0 / np.prod([nodes[j] - nodes[k] for k in range(len(nodes)) if k != j]) for j in range(len(nodes))])
    L = np.zeros((len(points), len(nodes)))
    for i, p in enumerate(points):
        d = p - nodes
        hit = np.where(np.abs(d) < 1e-15)[0]
        if hit.size:
            L[i, hit[0]] = 1.0
        else:
            L[i] = (w / d) / np.sum(w / d)
    return L


class GuidingCentreStep:
    """One step of the prototype (module comment), with q + 1 field nodes per Picard iteration."""

    def __init__(self, q, spin_angle_per_step, field_iterations):
        self.q = q
        self.field_iterations = field_iterations
        m = max(1, math.ceil(max(MIN_FINE, FINE_PER_RADIAN * spin_angle_per_step) / q))
        self.n = q * m
        self.m = m
        self.sigma, self.Q = chebyshev_grid(self.n)      # fine grid on [0, 1]
        self.slow = self.sigma[::m]                      # the field's nodes: every m-th fine point
        self.L = lagrange_matrix(self.slow, self.sigma)
        self.evals = 0
        self.iterations = []

    def __call__(self, R, K1, K2, h):
        tau = h * self.sigma
        y = np.tile(np.concatenate([R, K1, K2]), (self.n + 1, 1))
        y0 = y[0].copy()
        for it in range(MAX_PICARD):
            Rt, K1t, K2t = drift(y[:, 0:3], y[:, 3:6], y[:, 6:9], tau)
            if it < self.field_iterations:
                # The field's nodes on this iterate's guiding-centre path; later iterates move the path
                # by far less than rho and keep these (the Taylor sum reaches them from this path).
                G = guiding_centre(Rt, K1t, K2t)
                T = field_taylor(G[:: self.m])
                self.evals += self.q + 1
                Gi = self.L @ G[:: self.m]
                T0, T1, T2, T3 = (np.einsum("ij,j...->i...", self.L, t) for t in T)
            xi = Rt - Gi
            F = (T0 + np.einsum("nij,nj->ni", T1, xi) + 0.5 * np.einsum("nijk,nj,nk->ni", T2, xi, xi)
                 + np.einsum("nijkl,nj,nk,nl->ni", T3, xi, xi, xi) / 6.0)
            # y' = DPhi_{-t}(x(t)) P(x(t)): the backward drift's derivative along the kick, by a complex step.
            Rb, K1b, K2b = drift(Rt + 0j, K1t + 1j * COMPLEX_STEP * F, K2t + 0j, -tau + 0j)
            g = np.concatenate([Rb.imag, K1b.imag, K2b.imag], axis=1) / COMPLEX_STEP
            y_new = y0 + h * (self.Q @ g)
            change = np.max(np.abs(y_new - y)) / np.max(np.abs(y0))
            y = y_new
            if change < PICARD_TOL:
                break
        self.iterations.append(it + 1)
        Rh, K1h, K2h = drift(y[-1:, 0:3], y[-1:, 3:6], y[-1:, 6:9], np.array([h]))
        return Rh[0], K1h[0], K2h[0]


def velocity(K1, K2):
    return (J * K1 - B * K2) / D


def run(scene, q, angle, field_iterations):
    """The prototype on the pass from t = 0 to T_END at a step of `angle` rad of spin (the last one lands)."""
    s = bp.Stepper(scene, "lp-y4", 0.1).state  # the scene's initial state
    R, v, w = (np.asarray(s[k], dtype=float) for k in ("R", "v", "w"))
    K1, K2 = M * v + B * w, B * v + J * w
    h_nominal = angle / (S * np.linalg.norm(K1))
    n = max(1, math.ceil(T_END / h_nominal - 1e-9))
    h = T_END / n
    step = GuidingCentreStep(q, S * np.linalg.norm(K1) * h, field_iterations)
    for _ in range(n):
        R, K1, K2 = step(R, K1, K2, h)
    return R, velocity(K1, K2), step.evals, np.mean(step.iterations), max(step.iterations), h


# What the same passes cost the best exact splitting at fixed steps (below the resonance at pi) and GSL's
# rk8pd at a tolerance per step, in the same run: error and force evaluations per radian of spin.
SPLITTING, SPLITTING_ANGLES = "lp-kl6", [0.5, 1.0, 2.0, 2.75]
PEER, PEER_TOLS = "gsl-rk8pd", [1e-8, 1e-10, 1e-12, 1e-14]


def others(scene, ref):
    rows = []
    for method, kind, values in [(SPLITTING, "h", SPLITTING_ANGLES), (PEER, "tol", PEER_TOLS)]:
        if method not in [m["name"] for m in bp.methods()]:  # GSL is optional in the build
            print(f"| {method} | (not built) | | |")
            continue
        for value in values:
            if kind == "h":
                h = value / SPIN_RATE
                r = bp.integrate(scene, method, h=h, t_end=T_END, invariants=False, estimate_error=False)
                label = f"h = {h:.4g} ({value:g} rad)"
            else:
                r = bp.integrate(scene, method, tol=value, t_end=T_END, h=0.01, invariants=False, estimate_error=False)
                label = f"tol = {value:g}"
            b = r["bodies"][0]
            err = distance(b, ref)
            per_rad = b["force_evals"] / (SPIN_RATE * T_END)
            print(f"| {method} | {label} | {err:.2e} | {b['force_evals']} | {per_rad:.2f} |")
            rows.append([method, kind, repr(value), repr(err), b["force_evals"], repr(per_rad)])
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=8, help="q: the field is sampled at q + 1 nodes per step")
    parser.add_argument("--field-iterations", type=int, default=1,
                        help="Picard iterations that evaluate the field (later ones reuse the last)")
    parser.add_argument("--out", help="also write the table as CSV (atomically)")
    args = parser.parse_args()
    rows = []
    for label, kw in [("far pass, Kz = 0.1 (rho = 0.02)", dict(Kz=0.1, d=50.0)),
                      ("far pass, Kz = 5 (rho = 1)", dict(Kz=5.0, d=50.0))]:
        scene = bp.thesis_scene(m=M, B=B, J=J, K1=K1_0, **kw)
        ref = bp.integrate(scene, "odeint-rkf78", tol=1e-15, t_end=T_END, h=1e-3)["bodies"][0]
        print(f"\n{label}, t = {T_END:g}: error against odeint-rkf78 at tol 1e-15; q = {args.nodes}, "
              f"field evaluated in {args.field_iterations} Picard iteration(s) per step")
        print("| spin angle per step [rad] | h | error | order | field evals | per radian | Picard mean / max |")
        print("|---|---|---|---|---|---|---|")
        prev = None
        for angle in ANGLES:
            R, v, evals, it_mean, it_max, h = run(scene, args.nodes, angle,
                                                args.field_iterations)
            err = distance({"R": R, "v": v}, ref)
            order = "" if prev is None else f"{math.log(err / prev[1]) / math.log(h / prev[0]):.1f}"
            prev = (h, err)
            per_rad = evals / (SPIN_RATE * T_END)
            print(f"| {SPIN_RATE * h:.3g} | {h:.4g} | {err:.2e} | {order} | {evals} | {per_rad:.2f} | {it_mean:.1f} / {it_max} |")
            rows.append([kw["Kz"], args.nodes, args.field_iterations, repr(SPIN_RATE * h), repr(h), repr(err), evals, repr(per_rad), it_mean, it_max])
        print(f"\nthe same pass: {SPLITTING} at fixed steps and {PEER} at a tolerance per step")
        print("| method | step | error | force evals | per radian |")
        print("|---|---|---|---|---|")
        others(scene, ref)
    if args.out:
        write_csv(args.out, ["Kz", "q", "field_iterations", "spin_angle", "h", "err", "field_evals", "per_radian",
                             "picard_mean", "picard_max"], rows)


if __name__ == "__main__":
    main()
