"""Deflection of K1 against the impact parameter b of the incoming asymptote: a material point (B = 0)
against Rutherford's formula, and the spinning body of the thesis (B = 0.7), in the accuracy mode.

    /usr/bin/python3 examples/python/scattering.py [out.pdf] [--quick]

The scene is the thesis's (A = -2, m = J = 1, K1 = 5, L = 200, spin Kx = 2, Kz = 5) given by b, so d is
solved for it (docs/physics.md, Scattering: d is not the geometric impact parameter). Each run stops when
the body has left (back at its start distance); the deflection is the angle between the asymptotes.
"""
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bodypoint as bp  # noqa: E402

quick = "--quick" in sys.argv
out = next((a for a in sys.argv[1:] if not a.startswith("--")), "scattering.pdf")
A, m = -2.0, 1.0
bs = np.logspace(-2, 2, 9 if quick else 41)


def deflections(B):
    theta, v_inf = [], []
    for b in bs:
        scene = bp.thesis_scene(B=B, b=b)
        e = bp.encounter(scene, tol=1e-9)  # at 1e-10, B = 0.7 and b = 1 are out of auto's reach (1.8e-10)
        theta.append(e["deflection"])
        v_inf.append(e["v_inf_in"])
    return np.array(theta), np.array(v_inf)


theta0, v0 = deflections(0.0)
rutherford = 2 * np.arctan(abs(A) / (m * v0**2 * bs))
worst = float(np.max(np.abs(theta0 / rutherford - 1)))
theta7, _ = deflections(0.7)

fig, ax = plt.subplots(figsize=(6, 3.5))
ax.loglog(bs, rutherford, "k-", lw=1, label="Rutherford")
ax.loglog(bs, theta0, "o", ms=4, mfc="none", label="B = 0 (material point)")
ax.loglog(bs, theta7, "s-", ms=3, label="B = 0.7 (spinning body)")
ax.set_xlabel("impact parameter b")
ax.set_ylabel("deflection of K1 [rad]")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(out)
print(f"wrote {out}: B = 0 against Rutherford, largest relative difference {worst:.1e} over {len(bs)} b; "
      f"B = 0.7 at b = {bs[0]:.2g}: {theta7[0]:.3f} rad (material point {theta0[0]:.3f})")
if not worst < 1e-6:
    sys.exit(f"scattering.py: B = 0 misses Rutherford's deflection by {worst:.1e}")
