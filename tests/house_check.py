"""The house keeps itself (issue #82 item 5): what a change may not add without saying so.

1. No function longer than FUNCTION_LINES lines, C++ in lib/, adaptive/, experiments/, bench/ (a brace
   matcher over the text without comments and literals: a body opened after a parenthesised head at
   namespace or class scope) and Python in lib/, bench/, paper/, tests/ (the ast's functions).
2. A trait that only one family has (SINGLE_FAMILY_TRAITS) is read outside the catalogue
   (lib/core/drivers/bodypoint/run.cpp, run.hpp) only where TRAIT_READS lists it, at most that many times:
   a method's behaviour belongs on its catalogue row, not with its callers. The list is what remains to move
   (docs/developers.md, "The house"); it may shrink, never grow.
3. An exception is caught (`catch (`) only where CATCH_SITES lists it, at most that many times: errors go up
   to the few places that turn them into a message, an outcome or a step's answer.
4. A method's kind is asked (is_time_transformed, is_step_controlled) outside the catalogue only where
   KIND_CHECKS lists it. Each list holds the counts found: a file with fewer is a finding too, so that the
   list is lowered with the code.

Usage: house_check.py SOURCE_DIR. Prints each finding and exits 1 when there is one.
"""
import ast
import pathlib
import re
import sys

FUNCTION_LINES = 60
CPP_DIRS = ("lib", "adaptive", "experiments", "bench")
PY_DIRS = ("lib", "bench", "paper", "tests")
CATALOGUE = ("lib/core/drivers/bodypoint/run.cpp", "lib/core/drivers/bodypoint/run.hpp")
# Traits set for one family only (catalogue_traits, run.cpp): Thesis, TimeTransformed, Regularised, FarField.
SINGLE_FAMILY_TRAITS = re.compile(
    r"traits\.(frozen_gyroscopic_term|takes_omega_c|exact_in_fictitious_time)\b"
    r"|SearchStrategy::(field_pair|exact_pair)\b")
TRAIT_READS = {  # far-ip's search strategy (field_pair): its pair's basis, its search and its ladder's first step
    "adaptive/search/exact_pair.cpp": 1,
    "adaptive/search/runs.cpp": 1,
    "experiments/studies/work_precision.cpp": 1,
}
# A method's kind (is_time_transformed, is_step_controlled) asked outside the catalogue: what the row's functions
# (advance_to, advance_of, step_name, lands_on_output_times, takes_tolerance_per_step, refines_by_step, ...: run.hpp)
# do not yet answer.
KIND = re.compile(r"\b(is_time_transformed|is_step_controlled)\s*\(")
KIND_CHECKS = {
    "adaptive/search/rounding.cpp": 1,  # the rounding probe moves a fictitious step, or a fixed step's count
    "bench/bench_steps.cpp": 1,
    "experiments/cli/simulate.cpp": 1,  # the header names the step ds or h
    "experiments/studies/stress.cpp": 1,  # a fictitious step 10 fixed steps long
    "experiments/studies/work_precision.cpp": 2,  # the ladder of each kind
    "lib/api/integrate.cpp": 1,  # the message names the request's h as ds
}
CATCH_SITES = {
    "adaptive/search/search.hpp": 3,  # attempt(): a method's breakdown as a step's answer
    "bench/auto_costs.cpp": 1,
    "bench/bench_steps.cpp": 1,
    "bench/gsl_peer.cpp": 1,
    "experiments/cli/cli.cpp": 1,
    "experiments/cli/main.cpp": 2,  # the one-line message and exit code
    "experiments/cli/mpi_sweep.cpp": 3,
    "experiments/cli/process.cpp": 1,
    "experiments/cli/sweep.cpp": 2,
    "experiments/studies/work_precision.cpp": 1,
    "lib/api/integrate.cpp": 1,  # a run's Error as its outcome
    "lib/api/sweep.cpp": 3,  # a row's point named; a worker's error carried to the caller
    "lib/core/model/bodypoint/scene_file.cpp": 5,  # toml++'s errors with the file's line
    "lib/core/model/bodypoint/threads.hpp": 2,  # parallel_for: a call's error carried to the caller
    "lib/python/module.cpp": 5,  # Python's exceptions
}


def without_comments_and_literals(text):
    """The text with comments, strings and characters emptied and its lines kept."""
    out, i, n = [], 0, len(text)
    while i < n:
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i) + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif text.startswith('R"(', i):
            j = text.find(')"', i) + 2
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j
        elif text[i] == '"' or (text[i] == "'" and not (i > 0 and text[i - 1].isalnum())):  # 1'000 is a number
            quote, j = text[i], i + 1
            while j < n and text[j] != quote:
                j += 2 if text[j] == "\\" else 1
            out.append(quote * 2)
            i = j + 1
        else:
            out.append(text[i])
            i += 1
    return "".join(out)


CONTROL = re.compile(r".*\b(if|for|while|switch|catch|do|else)\s*\(")
SCOPE = re.compile(r"\bnamespace\b|\b(class|struct|union|enum)\b[^()]*$")


def long_cpp_functions(path):
    """(lines, first line, head) of each function body longer than FUNCTION_LINES."""
    stack, head, found = [], "", []
    for number, line in enumerate(without_comments_and_literals(path.read_text(encoding="utf-8")).split("\n"), 1):
        for ch in line:
            if ch == "{":
                h = head.strip()
                kind = "block"
                if SCOPE.search(h) or h.endswith('extern "C"'):
                    kind = "scope"
                elif ")" in h and not CONTROL.match(h.split("\n")[-1]) and all(k == "scope" for k, _, _ in stack):
                    kind = "function"
                stack.append((kind, number, " ".join(h.split())[-70:]))
                head = ""
            elif ch == "}":
                if stack:
                    kind, first, name = stack.pop()
                    if kind == "function" and number - first + 1 > FUNCTION_LINES:
                        found.append((number - first + 1, first, name))
                head = ""
            elif ch == ";":
                head = ""
            else:
                head += ch
        head += "\n"
    return found


def long_py_functions(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [(f.end_lineno - f.lineno + 1, f.lineno, f.name) for f in ast.walk(tree)
            if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)) and f.end_lineno - f.lineno + 1 > FUNCTION_LINES]


def sources(src, dirs, suffixes):
    for d in dirs:
        for f in sorted((src / d).rglob("*")):
            if f.is_file() and f.suffix in suffixes and "/build" not in f.as_posix():
                yield f, f.relative_to(src).as_posix()


def counted(src, pattern, allowed, what):
    problems = []
    for f, rel in sources(src, CPP_DIRS, (".cpp", ".hpp", ".h")):
        if rel in CATALOGUE:
            continue
        n = len(pattern.findall(without_comments_and_literals(f.read_text(encoding="utf-8"))))
        if n != allowed.get(rel, 0):  # more: say so; fewer: the list shrinks with the code
            problems.append(f"{rel}: {n} {what}, {allowed.get(rel, 0)} listed (tests/house_check.py)")
    return problems


def main():
    src = pathlib.Path(sys.argv[1]).resolve()
    problems, functions = [], 0
    for f, rel in sources(src, CPP_DIRS, (".cpp", ".hpp")):
        for lines, first, name in long_cpp_functions(f):
            problems.append(f"{rel}:{first}: a function of {lines} lines (at most {FUNCTION_LINES}): {name}")
        functions += 1
    for f, rel in sources(src, PY_DIRS, (".py",)):
        for lines, first, name in long_py_functions(f):
            problems.append(f"{rel}:{first}: {name} has {lines} lines (at most {FUNCTION_LINES})")
        functions += 1
    problems += counted(src, SINGLE_FAMILY_TRAITS, TRAIT_READS, "reads of a single family's trait")
    problems += counted(src, KIND, KIND_CHECKS, "checks of a method's kind")
    problems += counted(src, re.compile(r"\bcatch\s*\("), CATCH_SITES, "catch sites")
    for p in problems:
        print(p)
    print(f"{functions} files read, {len(problems)} findings")
    return 1 if problems or functions == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
