"""The folders show the layers: no file includes a header of a floor above its own.

Floors, from the ground up (docs/developers.md, "Architecture"):
  1 lib/core/model   2 lib/core/methods   3 lib/core/drivers   4 adaptive/   5 lib/api
  6 lib/python, experiments/ (the front ends; neither includes the other)
Every `#include "..."` of a project file is resolved the way the build resolves it: first beside the
file, then in the include roots (each floor's), and the header found must sit on the file's floor or
below. An include that resolves to nothing in the tree is a system or third-party header and is
skipped. The public API (floor 5) reaches the adaptive layer through one seam: only the files of SEAM
include its headers (the registry of its methods, and the search behind the accuracy mode), and the commands
and studies (experiments/) include none: they run on the public API. State arithmetic,
Richardson's rule and the accuracy mode's limits sit in the core (bodypoint/accuracy.hpp, model.hpp).
Usage: layers_check.py SOURCE_DIR. Prints each violation and exits 1 when there is one.
"""
import pathlib
import re
import sys

FLOORS = [  # (folder, floor); the longest matching folder decides a file's floor
    ("lib/core/model", 1),
    ("lib/core/methods", 2),
    ("lib/core/drivers", 3),
    ("adaptive", 4),
    ("lib/api", 5),
    ("lib/python", 6),
    ("experiments", 6),
]
# Where the build looks for "bodypoint/...", "search.hpp", "cli.hpp": each floor's include roots.
ROOTS = ["lib/core/model", "lib/core/methods", "lib/core/drivers", "adaptive", "lib/api",
         "experiments/cli", "experiments/studies"]
# The lib/api files that include an adaptive/ header (issue #82 item 3: at most two).
SEAM = {"lib/api/methods.cpp", "lib/api/integrate.cpp"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def floor_of(rel):
    best = None
    for folder, floor in FLOORS:
        if rel == folder or rel.startswith(folder + "/"):
            if best is None or len(folder) > len(best[0]):
                best = (folder, floor)
    return best


def resolve(src, name, file):
    here = file.parent / name
    if here.is_file():
        return here
    for root in ROOTS:
        candidate = src / root / name
        if candidate.is_file():
            return candidate
    return None


def main():
    src = pathlib.Path(sys.argv[1]).resolve()
    problems, checked = [], 0
    for folder, _ in FLOORS:
        for file in sorted((src / folder).rglob("*")):
            if file.suffix not in (".hpp", ".cpp", ".h") or not file.is_file():
                continue
            rel = file.relative_to(src).as_posix()
            own = floor_of(rel)
            for name in INCLUDE.findall(file.read_text(encoding="utf-8")):
                target = resolve(src, name, file)
                if target is None:
                    continue
                checked += 1
                theirs = floor_of(target.relative_to(src).as_posix())
                if theirs is None:
                    problems.append(f"{rel}: includes {name}, which is outside every floor")
                elif theirs[0] == "adaptive" and own[0] in ("lib/api", "experiments") and rel not in SEAM:
                    problems.append(f"{rel} includes {name} from adaptive/: only {sorted(SEAM)} may (the seam)")
                elif theirs[1] > own[1] or (theirs[1] == own[1] and theirs[0] != own[0] and own[1] == 6):
                    problems.append(f"{rel} (floor {own[1]}, {own[0]}) includes {name} from {theirs[0]} (floor {theirs[1]})")
    for p in problems:
        print(p)
    print(f"{checked} includes checked, {len(problems)} across a floor upwards")
    return 1 if problems or checked == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
