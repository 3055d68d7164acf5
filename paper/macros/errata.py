"""Section 'Errata': the printed thesis's sign error measured."""

import os

from macros.common import num, read_csv, sci


def errata(res, M):
    rows, _ = read_csv(os.path.join(res, "errata.csv"))
    for r in rows:
        v = num(r["value"])
        M.add(r["key"], f"{v:.2f}" if "Order" in r["key"] else sci(v))
