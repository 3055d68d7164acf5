"""The catalogue of methods as `bodypoint methods --csv` lists it (paper/build.sh writes it to
RESULTS_DIR/methods.csv): the paper's scripts group methods by the family the catalogue gives each,
never by the prefix of a name, so a method or a family added to the catalogue is drawn and counted
without touching them."""
import csv
import os

# The paper's names of the catalogue's families (bodypoint's family_key, run.hpp), where they differ
# from the catalogue's own (its family_name column): the thesis's seven are its five drift/kick schemes
# and Boost.Odeint's RK4 and AB4. A family not named here is called by the catalogue's name.
PAPER_FAMILY = {
    "thesis": "thesis's seven",
    "odeint": "thesis's seven",
    "lie-poisson": "Lie-Poisson",
    "kepler-split": "Kepler split",
    "time-transformed": "time-transformed",
    "regularised": "KS",
    "odeint-adaptive": "Boost.Odeint",
    "gsl": "GSL",
    "sundials": "SUNDIALS",
    "extrapolated": "logH+BS",
}

_rows = {}


def load(results):
    """Reads RESULTS_DIR/methods.csv; every other function here needs it."""
    with open(os.path.join(results, "methods.csv"), newline="") as f:
        for row in csv.DictReader(f):
            _rows[row["method"]] = row


def rows():
    """The catalogue's rows (methods.csv as DictReader read them), in its order."""
    return list(_rows.values())


def _paper_name(row):
    return PAPER_FAMILY.get(row["family"], row["family_name"])


def family(method):
    """The paper's family of a method, or None for a method not in the catalogue."""
    row = _rows.get(method)
    return _paper_name(row) if row else None


def families():
    """The paper's families, in the catalogue's order of their first methods."""
    out = []
    for row in _rows.values():
        if _paper_name(row) not in out:
            out.append(_paper_name(row))
    return out


def table(method):
    """The composition table a method composes its flows with (y4, kl6, ...), or "" for one without."""
    row = _rows.get(method)
    return row["table"] if row else ""


def has_fictitious_step(method):
    """True for the time-transformed and regularised methods (their step is the fictitious ds)."""
    row = _rows.get(method)
    return bool(row) and row["advance"] == "fictitious"
