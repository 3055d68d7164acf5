"""docs/figures/initial_conditions.svg: the thesis's initial conditions drawn from real runs (docs/physics.md,
"Initial conditions and scene parameters"). A repelling centre (A = -2), K1 = 5, spin Kx = 2, Kz = 5,
d = 3, L = 20: the material point (B = 0) starts on the line y = d - Kz/K1 and keeps it until the field
turns it; the spinning body (B = 0.7) starts at the same point, and its guiding centre
G = R + K1 x K2/|K1|^2 at height d, the line its mean motion follows.

    PYTHONPATH=build/python /usr/bin/python3 docs/figures/initial_conditions.py [out.svg]
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bodypoint as bp  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else "docs/figures/initial_conditions.svg"
params = dict(A=-2.0, K1=5.0, Kx=2.0, Kz=5.0, d=3.0, L=20.0)
times = np.linspace(0.0, 6.0, 601)
fig, ax = plt.subplots(figsize=(6.3, 3.6))
for B, style, label in ((0.0, "C0-", "B = 0 (material point)"), (0.7, "C1-", "B = 0.7 (spinning body)")):
    scene = bp.thesis_scene(B=B, **params)
    tr = bp.trajectory(scene, "lp-kl8", 1e-3, times)[0]
    ax.plot(tr["R"][:, 0], tr["R"][:, 1], style, lw=1.2, label=label)
y0 = params["d"] - params["Kz"] / params["K1"]
L = params["L"]
ax.axhline(0.0, color="0.6", lw=0.6)
ax.plot([-L, 8], [params["d"]] * 2, "k:", lw=0.8, label="guiding centre's line y = d (B != 0)")
ax.plot(0, 0, "k*", ms=10)
ax.annotate("centre at the origin", (0.4, -0.8), fontsize=8)
ax.plot(-L, y0, "ko", ms=4)
ax.annotate("R(0) = (-L, d - Kz/K1, 0)", (-L + 0.4, y0 - 0.75), fontsize=8)
ax.annotate("", xy=(-L + 4, -1.6), xytext=(-L, -1.6), arrowprops=dict(arrowstyle="->"))
ax.annotate("K1(0) = K1 i", (-L + 4.4, -1.75), fontsize=8)
ax.annotate("", xy=(-L - 1.0, y0), xytext=(-L - 1.0, 0), arrowprops=dict(arrowstyle="<->", lw=0.8))
ax.annotate("b = |d - Kz/K1|\n(B = 0)", (-L - 7.8, 0.5 * y0 - 0.35), fontsize=8)
ax.set_xlim(-L - 8, 9)
ax.set_ylim(-2.3, 7.5)
ax.set_xlabel("x")
ax.set_ylabel("y")
ax.legend(fontsize=8, loc="upper right")
fig.tight_layout()
fig.savefig(out)
print(f"wrote {out}")
