#!/usr/bin/env python3
"""Checks of the research appendix (ctest runs both; see tests/CMakeLists.txt).

usage: check_paper.py literals paper/bodypoint.tex
       check_paper.py pdf paper/build
       check_paper.py contended paper/results-quick OUT quick

literals: fails if the body of the .tex types a number that is not a scene parameter or a reference to
          the thesis (every measured figure must come from generated/macros.tex).
pdf:      fails unless bodypoint.pdf exists with every required section, and the LaTeX log has no
          undefined reference or citation and no overfull box wider than MAX_OVERFULL_PT; the text
          states no number as "n/a" (a number it promised and lost: the sentence must say why in
          words), and a copy whose parts lost every time to the timing rules carries the draft stamp
          and its list (make_macros.py's ContendedStamp, ContendedNotice).
contended: builds in OUT the copy a fully contended machine would make of the results directory (every
          time flagged, paper/contended_copy.py; MODE quick or full as the results were made) and checks it
          as `pdf` does, its stamp and list included: the pages a busy machine's build lays out, checked
          on any machine.
"""
import os
import re
import shutil
import subprocess
import sys

import contended_copy

# Inputs, not measurements, that the text may type: the thesis's scene parameters (table 3.1: d = 10,
# L = 200, B = 0.7; the sweeps' d = 50, T = hn = 25, n = 250000, t = 50; appendix set P1.2's J = 0.2;
# the close scene's Kz = 0.1, d = 0.05, t = 80; the convergence scenes' L = 20, t = 30).
# The scattering study's couplings B = 0.2, 0.5, 0.7, 0.9 are inputs too, and so are the thesis code's
# harnesses' literal settings: v0 = (7.058, 0, 6.86), w0 = (-2.941, 0, -9.8), d' up to 199, Kx = -10, -9.9,
# ..., 10.1.
# Constants of the methods, stated as their definition: the time-step constant's ratio 16, the accuracy
# mode's aim 0.3 and acceptance 0.8 of TOL, logh-bs's largest substep count 18; and the thesis's grid
# sizes (40 values of d, 201 of Kx).
ALLOWED = {"10", "200", "0.7", "50", "25", "250000", "0.2", "0.1", "0.05", "80", "20", "30", "0.5", "0.9",
           "7.058", "6.86", "2.941", "9.8", "199", "9.9", "10.1", "16", "0.3", "0.8", "18", "40", "201"}
# Powers of ten are step sizes, targets and tolerances the reader or a recipe chooses (h = 10^{-4},
# targets 10^{-7}, the reference's tolerance 10^{-18}), never results.
POWER_OF_TEN = re.compile(r"10\^\{?-?\d+\}?")
# References into the thesis ("eq.~1.10", "table 3.1", "fig.~4.1--4.2", "P1.2") and pieces of names
# that carry digits (\cmd{lp-y4}, \texttt{...}).
THESIS_REF = re.compile(r"(?i)(eqs?\.|tables?|figs?\.|sec\.|chapter|appendix|set|sets|P)[~\s]*\d+(\.\d+)?(--\d+(\.\d+)?)?")
NAMES = re.compile(r"\\(cmd|texttt|cite|citet|citep|ref|label|eqref|includegraphics|tablebody|input|setlength|begin|end)"
                   r"(\[[^\]]*\])?\{[^}]*\}(\{[^}]*\})?")
NUMBER = re.compile(r"(?<![A-Za-z\\_^{])\d+(\.\d+)?")
MAX_OVERFULL_PT = 10.0
SECTIONS = ["Introduction", "The model and its corrected equations", "Errata", "Methods", "Chapter 4 reproduced",
            "Close encounters", "Work against precision", "Numerical stability", "Long-time behaviour", "Scattering of a spinning body",
            "Conclusions"]


def body_of(tex):
    text = tex[tex.index("\\begin{document}"):]
    return "\n".join(re.sub(r"(?<!\\)%.*", "", line) for line in text.splitlines())


def literals(path):
    with open(path) as f:
        text = body_of(f.read())
    text = re.sub(r"\\verb\|[^|]*\|", " ", text)  # quoted code, e.g. Math.pow(r, 3.0/2.0)
    text = NAMES.sub(" ", text)
    text = THESIS_REF.sub(" ", text)
    text = POWER_OF_TEN.sub(" ", text)
    bad = []
    for lineno, line in enumerate(text.splitlines(), 1):
        for m in NUMBER.finditer(line):
            tok = m.group(0)
            if len(tok) == 1 or tok in ALLOWED:  # single digits: orders, counts of stages, ordinals
                continue
            bad.append(f"  line {lineno} of the body: {tok!r} in: {line.strip()[:100]}")
    if bad:
        print(f"{path}: literal numbers (write them as macros from paper/make_macros.py):")
        print("\n".join(bad))
        return 1
    print(f"{path}: no literal measured number")
    return 0


def pdf(build):
    failures = []
    try:
        with open(f"{build}/bodypoint.pdf", "rb") as f:
            if f.read(5) != b"%PDF-":
                failures.append("bodypoint.pdf is not a PDF")
    except OSError as e:
        failures.append(f"no PDF: {e}")
    with open(f"{build}/bodypoint.log", errors="replace") as f:
        log = f.read()
    for pattern in [r"Reference `[^']*' on page \d+ undefined", r"Citation `[^']*' on page \d+ undefined",
                    r"There were undefined references", r"Undefined control sequence"]:
        for m in re.finditer(pattern, log):
            failures.append(f"log: {m.group(0)}")
    for m in re.finditer(r"Overfull \\[hv]box \(([\d.]+)pt too (wide|high)\)", log):
        if float(m.group(1)) > MAX_OVERFULL_PT:
            failures.append(f"log: overfull box of {m.group(1)} pt (limit {MAX_OVERFULL_PT} pt)")
    with open(f"{build}/bodypoint.aux", errors="replace") as f:
        aux = f.read()
    for title in SECTIONS:
        if not re.search(r"\\contentsline \{section\}\{\\numberline \{\d+\}" + re.escape(title) + r"\}", aux):
            failures.append(f"missing section: {title}")
    failures += repeated_pairs(build)
    failures += claims_without_verdict(build)
    failures += numbers_lost(build)
    pages = re.search(r"Output written on bodypoint\.pdf \((\d+) pages", log)
    if failures:
        print("\n".join(failures))
        return 1
    print(f"{build}/bodypoint.pdf: {pages.group(1) if pages else '?'} pages, {len(SECTIONS)} sections, "
          f"no undefined reference or citation, no overfull box above {MAX_OVERFULL_PT} pt")
    return 0


def repeated_pairs(build):
    """Generated sentences that name one thing twice: "\\A\\ and \\B" in the text where both macros
    expand to the same words ("lp-verlet-dkd and lp-verlet-dkd"); equal numbers are measurements."""
    with open(f"{build}/generated/macros.tex") as f:
        defs = dict(re.findall(r"\\newcommand\{\\([A-Za-z]+)\}\{(.*)\}$", f.read(), re.M))
    with open(f"{build}/bodypoint.tex") as f:
        body = body_of(f.read())
    found = []
    for a, b in re.findall(r"\\([A-Za-z]+)\\?\s+and\s+\\([A-Za-z]+)", body):
        if a in defs and b in defs and defs[a] == defs[b] and not defs[a].startswith("\\ensuremath"):
            found.append(f"text: \\{a} and \\{b} both read '{defs[a]}'")
    return found


def numbers_lost(build):
    """Macros the text uses that read "n/a" where it promised a number ("agree within a factor of n/a"),
    and a copy whose list of parts without a time is not empty but whose stamp is (or the other way)."""
    with open(f"{build}/generated/macros.tex") as f:
        defs = dict(re.findall(r"\\newcommand\{\\([A-Za-z]+)\}\{(.*)\}$", f.read(), re.M))
    with open(f"{build}/bodypoint.tex") as f:
        used = set(re.findall(r"\\([A-Za-z]+)", body_of(f.read())))
    found = [f"text: \\{name} reads n/a" for name in sorted(used & set(defs))
             if re.fullmatch(r"(\\ensuremath\{)?n/a\}?", defs[name])]
    if bool(defs.get("ContendedNotice")) != bool(defs.get("ContendedStamp")):
        found.append("a contended copy without its stamp and its list (ContendedNotice, ContendedStamp)")
    return found


def claims_without_verdict(build):
    """The table of the thesis's claims: each row must carry a verdict in both columns (as published,
    corrected) that starts with yes, partly or no, or says why none: "tied" (every point a tie of
    deviations that agree to more digits than the arithmetic decides), "n/a" (RK4 and AB4 diverge
    there too) or "untimed" (a cost claim whose times were all flagged: the machine was contended, as
    under a parallel test run); "--" means a CSV it reads had no data for it."""
    try:
        with open(f"{build}/generated/tab_claims.tex") as f:
            rows = [line for line in f if line.strip()]
    except OSError as e:
        return [f"no table of claims: {e}"]
    found = [] if rows else ["the table of claims is empty"]
    for line in rows:
        cells = [c.strip() for c in line.rstrip().rstrip("\\").split(" & ")]
        if len(cells) != 5 or not all(re.match(r"(yes|partly|no|tied|n/a|untimed)\b", c) for c in cells[3:]):
            found.append(f"claim without a verdict: {line.strip()[:100]}")
    return found


def contended(results, out, mode):
    """The worst case of a busy machine's build (every time flagged) made from `results` in `out`, and
    checked as pdf() checks a build; it must carry the draft stamp and its list."""
    here = os.path.dirname(os.path.abspath(__file__))
    contended_copy.flag_every_time(results, os.path.join(out, "results"))
    for step in [["make_figures.py", os.path.join(out, "results"), os.path.join(out, "figures")],
                 ["make_macros.py", os.path.join(out, "results"), os.path.join(out, "generated"), mode,
                  os.path.join(out, "figures")]]:
        subprocess.run([sys.executable, os.path.join(here, step[0])] + step[1:], check=True, stdout=subprocess.DEVNULL)
    for name in ["bodypoint.tex", "bodypoint.bib"]:
        shutil.copy(os.path.join(here, name), out)
    latex = subprocess.run(["latexmk", "-pdf", "-interaction=nonstopmode", "-halt-on-error", "bodypoint.tex"],
                           cwd=out, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if latex.returncode != 0:
        print(latex.stdout[-3000:])
        print(f"{out}: LaTeX failed on the contended copy")
        return 1
    with open(os.path.join(out, "generated", "macros.tex")) as f:
        if not re.search(r"\\newcommand\{\\ContendedStamp\}\{\S", f.read()):
            print(f"{out}: the contended copy has no draft stamp")
            return 1
    return pdf(out)


def main():
    args = sys.argv[1:]
    if args[:1] == ["contended"] and len(args) == 4:
        sys.exit(contended(*args[1:]))
    if len(args) != 2 or args[0] not in ("literals", "pdf"):
        sys.exit(__doc__)
    sys.exit(literals(args[1]) if args[0] == "literals" else pdf(args[1]))


if __name__ == "__main__":
    main()
