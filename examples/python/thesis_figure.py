"""The thesis's fig. 4.1-4.2 in Python: the relative energy error of the final state against the
impact-parameter-like d (table 3.1, h = 1e-4), for the thesis's Forest-Ruth 4 (which freezes the
gyroscopic term and is first order for B != 0) and the exact Lie-Poisson Yoshida 4 of the same table.

    /usr/bin/python3 examples/python/thesis_figure.py [out.pdf] [--quick]
(PYTHONPATH=build/python in the build tree, or after `cmake --install build --component python`.)
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bodypoint as bp  # noqa: E402

quick = "--quick" in sys.argv
out = next((a for a in sys.argv[1:] if not a.startswith("--")), "thesis_figure.pdf")
d = np.arange(5.0, 201.0, 15.0 if quick else 5.0)
steps = 25000 if quick else 250000  # the thesis's runs: n = 250000 steps of h = 1e-4 (T = 25)
cols = bp.sweep({"d": d}, ["thesis-fr4", "lp-y4"], h=1e-4, steps=steps, threads=2)

fig, ax = plt.subplots(figsize=(6, 3.5))
for method, label in (("thesis-fr4", "thesis's Forest-Ruth 4 (frozen gyroscopic term)"),
                      ("lp-y4", "exact Lie-Poisson Yoshida 4")):
    rows = np.array(cols["method"]) == method
    ax.semilogy(cols["d"][rows], cols["max_rel_dE"][rows], "o-", ms=3, label=label)
ax.set_xlabel("d")
ax.set_ylabel(r"max $|E_i - E_0|/|E_0|$")
ax.set_title(f"table 3.1, h = 1e-4, n = {steps}")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(out)
worst = {m: float(np.max(cols["max_rel_dE"][np.array(cols["method"]) == m])) for m in ("thesis-fr4", "lp-y4")}
print(f"wrote {out}: largest energy error thesis-fr4 {worst['thesis-fr4']:.2e}, lp-y4 {worst['lp-y4']:.2e}")
