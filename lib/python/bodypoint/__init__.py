"""bodypoint: the dynamics of a body-point (a particle with translational and rotational degrees of
freedom) in Coulomb fields, integrated by the bodypoint C++ library.

The model, the equations and the meaning of every parameter are in docs/physics.md of the project;
the method catalogue is ``methods()``. Every result is a plain dict of numbers and numpy arrays; a
sweep's result is a dict of equal-length columns (``pandas.DataFrame(bodypoint.sweep(...))``).
Invalid input raises ``bodypoint.Error`` (a ``ValueError``) with the library's one-line reason;
anything that happens to a valid run is reported in its ``outcome`` and ``reason``.

    import bodypoint as bp
    scene = bp.thesis_scene()                      # the thesis's table 3.1
    r = bp.integrate(scene, "lp-y4", h=1e-3, t_end=50)
    r["bodies"][0]["R"]                            # numpy array, position at t = 50
    r = bp.integrate(scene, tol=1e-10, t_end=50)   # accuracy mode: method and step chosen
"""
import enum as _enum
import json as _json
import numbers as _numbers
import os as _os
import sys as _sys
import time as _time

from numpy import bool_ as _np_bool

from ._bodypoint import Error, Scene
from . import _bodypoint as _core

__all__ = ["Error", "Scene", "Outcome", "Stepper", "methods", "scene_parameters", "thesis_scene", "read_scene",
           "parse_scene", "integrate", "trajectory", "sweep", "encounter", "DEFAULT_MAX_SECONDS", "__version__"]

# A call's budget of wall-clock time unless given, the command line's (a day): past it the call raises
# bodypoint.Error; Ctrl-C raises KeyboardInterrupt within a fraction of a second (the runs poll it).
DEFAULT_MAX_SECONDS = 86400.0

__version__ = _core.__version__  # the project's (CMakeLists.txt); the build's git revision is __revision__
__revision__ = _core.__revision__


class Outcome(str, _enum.Enum):
    """What happened to a run (docs/physics.md, "Resolution and accuracy flags"). A str: an outcome
    compares equal to its name, as the dicts hold it (``r["outcome"] == Outcome.ok``)."""
    ok = "ok"
    diverged = "diverged"
    unresolved = "unresolved"
    inaccurate = "inaccurate"
    collision = "collision"
    incomplete = "incomplete"
    refused = "refused"
    failed = "failed"


def _number(name, value, *, optional=False):
    """value as a float, or bodypoint.Error naming the quantity (a bool or a text is not a number)."""
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, _numbers.Real):
        raise Error(f"{name} must be a number, got {type(value).__name__}")
    try:
        return float(value)
    except OverflowError:
        raise Error(f"{name} must be a finite number, got {value!r:.40}") from None


def _count(name, value, *, optional=False):
    """value as an int (a float with a whole value, such as 1e5, counts), or bodypoint.Error."""
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, _numbers.Real):
        raise Error(f"{name} must be a whole number, got {type(value).__name__}")
    if not isinstance(value, _numbers.Integral) and not _number(name, value).is_integer():
        raise Error(f"{name} must be a whole number, got {value!r}")
    if abs(int(value)) >= 2**63:  # a C++ long
        raise Error(f"{name} must be below 2^63, got {value!r:.40}")
    return int(value)


def _index(name, value):
    """value as an index (a whole number >= 0), or bodypoint.Error naming it."""
    i = _count(name, value)
    if i < 0:
        raise Error(f"{name} must be a whole number >= 0, got {i}")
    return i


def _numbers_of(name, values):
    """A sequence of numbers; a single number is a sequence of one."""
    if isinstance(values, _numbers.Real) and not isinstance(values, bool):
        return [_number(name, values)]
    if isinstance(values, (str, bytes)):
        raise Error(f"{name} must be a number or a sequence of numbers, got {type(values).__name__}")
    try:
        items = list(values)
    except TypeError:
        raise Error(f"{name} must be a number or a sequence of numbers, got {type(values).__name__}") from None
    return [_number(name, v) for v in items]


def _flag(name, value):
    """A yes/no keyword: True or False (a text such as "no" would read as True)."""
    if not isinstance(value, (bool, _np_bool)):
        raise Error(f"{name} must be True or False, got {value!r:.40}")
    return bool(value)


def _text(name, value):
    if not isinstance(value, str):
        raise Error(f"{name} must be a text, got {type(value).__name__}")
    return value


def _texts(name, values):
    """A list of texts; a single text is a list of one."""
    if isinstance(values, str):
        return [values]
    try:
        return [_text(name, v) for v in values]
    except TypeError:
        raise Error(f"{name} must be a text or a list of texts, got {type(values).__name__}") from None


def _scene(scene):
    if not isinstance(scene, Scene):
        raise Error(f"scene must be a bodypoint.Scene (thesis_scene(), read_scene(), Scene(...)), got {type(scene).__name__}")
    return scene


# Defaults of a body given as a dict (a scene file states them): a material point of unit mass and
# moment of inertia, not spinning.
_BODY_DEFAULTS = {"m": 1.0, "B": 0.0, "J": 1.0}


def _toml_value(where, key, value):
    """A value of a Scene dict as scene-file (TOML) text: a number, a text or a sequence of numbers."""
    if isinstance(value, str):
        return _json.dumps(value)
    if isinstance(value, (bool, bytes)) or value is None:
        raise Error(f"bodypoint.Scene: {where}: '{key}' must be a number or a sequence of 3 numbers, got {value!r}")
    if isinstance(value, _numbers.Real):
        x = _number(f"bodypoint.Scene: {where}: '{key}'", value)
        return "nan" if x != x else ("inf" if x == float("inf") else ("-inf" if x == -float("inf") else repr(x)))
    try:
        items = list(value)
    except TypeError:
        raise Error(f"bodypoint.Scene: {where}: '{key}' must be a number or a sequence of 3 numbers, "
                    f"got {type(value).__name__}") from None
    return "[" + ", ".join(_toml_value(where, key, x) for x in items) + "]"


def _scene_toml(centres, bodies):
    """The scene-file text of a Scene's dicts (the library reads it: the scene files' keys and checks)."""
    lines = []
    for kind, entries in (("centre", centres), ("body", bodies)):
        if isinstance(entries, (str, bytes, dict)) or not hasattr(entries, "__iter__"):
            raise Error(f"bodypoint.Scene: the {kind} entries must be a list of dicts, got {type(entries).__name__}")
        for i, entry in enumerate(entries):
            where = f"{kind} {i + 1}"
            if not isinstance(entry, dict):
                raise Error(f"bodypoint.Scene: {where} must be a dict, got {type(entry).__name__}")
            entry = dict(entry)
            if kind == "body":
                entry = {**_BODY_DEFAULTS, **entry}
                if ("R" in entry or "v" in entry) and "w" not in entry:
                    entry["w"] = (0.0, 0.0, 0.0)
            lines.append(f"[[{kind}]]")
            for key, value in entry.items():
                if not isinstance(key, str):
                    raise Error(f"bodypoint.Scene: {where}: a key must be a text, got {key!r}")
                lines.append(f"{_json.dumps(key)} = {_toml_value(where, key, value)}")
    return "\n".join(lines) + "\n"


def methods():
    """Every method of the catalogue: dicts with name, family, order, stages, evals_per_step, description,
    geometry (what its flows preserve, as `bodypoint methods --csv`), symmetric (a splitting whose step is its
    own adjoint) and table (a splitting's composition table, "" otherwise)."""
    return _core._methods()


def scene_parameters():
    """The names of the thesis scene's parameters (A, m, B, J, d, L, K1, Kx, Kz)."""
    return _core._scene_parameters()


def thesis_scene(**params):
    """The thesis's scene: one centre at the origin and one body-point, table 3.1 unless changed.

    Keywords: any of scene_parameters() (A, m, B, J, K1, Kx, Kz, d, L, phase), and the asymptotic
    data b (the incoming asymptote's impact parameter; d is solved for it), v_inf (the speed at
    infinity; K1 is solved for it) and arrival_phase (the helix's phase when the guiding centre
    reaches its periapsis; phase is solved for it). docs/physics.md says what each means: d is *not*
    the geometric impact parameter.
    """
    scene = _core._thesis_scene(params)
    scene._thesis = dict(params)  # encounter() doubles its start distance L for the 1/L part of the error
    return scene


def read_scene(path):
    """A scene from a TOML scene file (the project's scenes/ folder has examples)."""
    path = _os.fspath(path)
    text = _core._read_scene_text(path)
    scene = _core._parse_scene(text, path)
    scene._toml = (text, path)  # sweep(scene=) varies the file's own keys (body.d of a thesis-form body too)
    return scene


def parse_scene(text):
    """A scene from the text of a TOML scene file."""
    scene = _core._parse_scene(_text("text", text))
    scene._toml = (text, "<string>")
    return scene


def _sweep_scene(scene, axes, base, force_law):
    """sweep()'s scene: (scene-file text and name, axes, base, force law). A thesis_scene() is swept as the
    thesis's parameters (its keywords fixed, its asymptotic data as one-value axes); any other Scene
    by its file's keys (read_scene(), parse_scene()) or, built from dicts, by the keys of its states."""
    if isinstance(scene, (str, _os.PathLike)):
        scene = read_scene(scene)
    _scene(scene)
    thesis = getattr(scene, "_thesis", None)
    if thesis is not None:
        data = ("b", "v_inf", "arrival_phase")
        named = [k for k, _ in axes]
        axes = axes + [(k, [_number(k, v)]) for k, v in thesis.items() if k in data and k not in named]
        fixed = {k: v for k, v in thesis.items() if k not in data and k != "force_law"}
        return None, axes, {**fixed, **base}, thesis.get("force_law", force_law)
    toml = getattr(scene, "_toml", None) or (_scene_toml(scene.centres, scene.bodies), "bodypoint.Scene")
    return toml, axes, base, force_law


def integrate(scene, method="auto", *, h=None, steps=None, t_end=None, tol=None, invariants=True,
              omega_c=None, events=(), stop_at=(), max_energy_error=_core.DEFAULT_MAX_ENERGY_ERROR,
              estimate_error=True, max_error=_core.DEFAULT_MAX_ERROR, max_seconds=DEFAULT_MAX_SECONDS):
    """Integrates every body of the scene; returns a dict (outcome, reason, force_evals, wall_s, bodies).

    How time advances follows the method's kind, as on the command line:
      fixed-step methods: steps of h (``steps`` of them, or to ``t_end`` exactly with the largest
          step <= h that lands on it);
      time-transformed methods (logh-*, ttl-*, ks): fictitious step ds = h, to t_end exactly or
          ``steps`` fictitious steps;
      step-size-controlled peers (odeint-*, gsl-*): ``tol`` per step to t_end, first trial step h;
      ``tol`` with any other method, or method "auto": the accuracy mode, the final state's relative
          error at most tol at t_end (the step, and for "auto" the method, are chosen).
    ``omega_c``: the time-step constant c of logh-* and ttl-* (physical step <= ds/c; default: from the
    scene's spin-orbit rate), refused for any other method and in the accuracy mode.
    Each body's dict has its name and the keys of ``bodypoint simulate --json`` (docs/guide.md, "Output
    fields"): method, outcome, reason, h, the final R, v, w (numpy arrays), t_end, steps, the invariants'
    largest deviations (max_rel_dE, max_rel_dK2sq, max_abs_dK2Q), force_evals (the delivered run's),
    total_force_evals (with the accuracy mode's search, the error estimate and the events), the
    accuracy mode's search (tol, h_chosen, search_runs, search_force_evals) and its choice (chosen),
    and the events asked for (the forms of the command line's --event: closest, closest:K, local-min,
    r=V, r:K=V, x=X, y=Y, z=Z, plane=nx,ny,nz,offset, departure, arrival), located on the method's own
    steps: events (event, t, r, R, v, w), event_force_evals; ``stop_at``: events that end the run at
    their first hit (stopped_by).
    Each body's ``err_estimate`` is the estimated relative error of its final state, max(|dR|/|R|,
    |dv|/|v|): from a companion run at up to twice the step (about half a run), or, where that pair cannot
    be trusted, at half the step (a tenth of a peer's tolerance), or the accuracy mode's; None when there is none, ``err_basis`` saying how it was obtained
    or why there is none (``estimate_error=False``: not asked for). ``warnings``: flags the estimate
    overruled.
    The outcome is "ok", or the flag of a run whose numbers bodypoint does not vouch for: "diverged",
    "unresolved" (a step too large for the spin or the encounter), "inaccurate" (an energy error above
    ``max_energy_error``, or an estimated error above ``max_error``; float("inf") lifts a bound),
    "collision"; or "refused"/"failed" without a run (docs/physics.md, "Resolution and accuracy flags").
    """
    return _with_outcomes(_core._integrate(_scene(scene), _text("method", method), _number("h", h, optional=True),
                            _count("steps", steps, optional=True), _number("t_end", t_end, optional=True),
                            _number("tol", tol, optional=True), _flag("invariants", invariants), _number("omega_c", omega_c, optional=True),
                            _texts("events", events), _texts("stop_at", stop_at),
                            _number("max_energy_error", max_energy_error), _flag("estimate_error", estimate_error),
                            _number("max_error", max_error), _number("max_seconds", max_seconds)))


def _with_outcomes(result):
    """A result whose outcomes are Outcome values (a str enum: "ok" == Outcome.ok), as advance_to's."""
    result["outcome"] = Outcome(result["outcome"])
    for body in result.get("bodies", ()):
        body["outcome"] = Outcome(body["outcome"])
    return result


def _in_notebook():
    """Whether this runs in a Jupyter kernel (its stderr is shown in the notebook)."""
    shell = _sys.modules.get("IPython")
    ip = shell.get_ipython() if shell and hasattr(shell, "get_ipython") else None
    return ip is not None and type(ip).__name__ == "ZMQInteractiveShell"


class _Progress:
    """A one-line display of a long call on stderr, rewritten in place ("sweep: 120/800 rows (15 %),
    3 s, ~20 s left"); silent for calls that end within a second."""

    SILENT_SECONDS = 1.0

    def __init__(self, label, unit):
        self.label, self.unit, self.start, self.shown = label, unit, _time.monotonic(), False

    def __call__(self, done, total):
        elapsed = _time.monotonic() - self.start
        if not self.shown and (done == total or elapsed < self.SILENT_SECONDS):
            return
        left = f", ~{elapsed * (total - done) / done:.0f} s left" if 0 < done < total else ""
        _sys.stderr.write(f"\r{self.label}: {done}/{total} {self.unit} ({100 * done // max(total, 1)} %), "
                          f"{elapsed:.0f} s{left}   " + ("\n" if done == total else ""))
        _sys.stderr.flush()
        self.shown = True


def _progress(progress, label, unit):
    """The progress display of a long call: ``progress`` None (the default) shows it where stderr is a
    terminal or in a notebook, not in a script whose stderr is a file or a pipe, nor under CI; True or
    False decide."""
    if progress is None:
        try:
            terminal = _sys.stderr.isatty()
        except (AttributeError, ValueError):
            terminal = False
        progress = (terminal or _in_notebook()) and not _os.environ.get("CI")
    return _Progress(label, unit) if _flag("progress", progress) else None


def trajectory(scene, method="auto", step=None, times=(), *, tol=None, omega_c=None, max_seconds=DEFAULT_MAX_SECONDS,
               progress=None):
    """Each body's state at the given times (increasing, >= 0), by a Stepper landing on every one.

    ``step``: the step h of a fixed-step method (the largest step <= h that lands on every requested
    time), the fictitious step ds of a time-transformed one, or the tolerance per step of a
    step-size-controlled peer. Or ``tol`` (method "auto" or any method the accuracy mode takes): the
    method, its step and time-step constant are the accuracy mode's for a run to the last time
    (``h_chosen``, ``err_estimate`` of that run, ``search_force_evals``), then followed segment by segment.
    A list of dicts per body: name, method, outcome and reason (a segment that was not ok ends the rows
    there: NaN after it; "unresolved" and "inaccurate" keep the state that was computed), t (n,), R, v,
    w (n, 3), E (n,) the energy at each time, max_rel_dE its largest deviation from the start's,
    force_evals, steps. ``progress``: a line on stderr while it runs (None: where stderr is a terminal
    or a notebook; see sweep())."""
    return _core._trajectory(_scene(scene), _text("method", method), _number("step", step, optional=True),
                             [_number("a time", t) for t in times], _number("omega_c", omega_c, optional=True),
                             _number("tol", tol, optional=True), _number("max_seconds", max_seconds),
                             _progress(progress, "trajectory", "times"))


def sweep(axes, methods, *, h=1e-4, steps=0, t_end=0.0, tol=1e-10, accuracy=None, threads=None, scattering=False,
          force_law="coulomb", max_energy_error=_core.DEFAULT_MAX_ENERGY_ERROR, estimate_error=True,
          max_error=_core.DEFAULT_MAX_ERROR, max_seconds=DEFAULT_MAX_SECONDS, scene=None, progress=None, **base):
    """Runs a scene (the thesis's unless ``scene`` is given) over a grid of parameters and methods;
    returns columns.

    ``axes``: {parameter: values} in order (one axis, or a grid of every combination, the last axis
    fastest); a parameter is h, one of scene_parameters(), b, v_inf or arrival_phase. ``scene``: a
    Scene or a scene file's path; its axes are then the file's keys, "centre2.A", "centre1.position.x",
    "body.B" (every body), "body2.d" or "NAME.B" (a body by name), "body1.R.x" (docs/guide.md, Sweeps),
    and a scene of several bodies gives a row per body (the column "body", from 1). A thesis_scene()
    is swept as the thesis's parameters. ``methods``: names, a list of
    names separated by commas, "fixed" (every fixed-step method but the Kepler split) or "all", as
    ``bodypoint sweep --methods`` takes them, and "auto": the accuracy mode chooses each row's method
    (column chosen), at ``accuracy``, or listed alone without it at ``tol``; auto's rows share one plan, each
    starting at the step of its nearest pilot row (err_basis names it; docs/physics.md, "A map at an accuracy"). ``base``: fixed scene parameters, and fixed asymptotic data (b, v_inf,
    arrival_phase: solved for at every point, a column each, as ``bodypoint sweep --b``); ``force_law`` as
    thesis_scene()'s. Steps of h: ``steps`` of them, or to ``t_end``; ``tol``: the step-size-controlled
    peers' tolerance per step. ``accuracy``: the accuracy mode, every other method delivering this
    relative error of the final state at ``t_end`` (its step searched per row: columns h_chosen, omega_c,
    search_force_evals). ``threads``: every core unless
    given (0 too, as on the command line). The columns are those of ``bodypoint sweep``'s CSV (docs/guide.md): one per axis, method,
    max_rel_dE, max_rel_dK2sq, max_abs_dK2Q, Rx..Rz, force_evals, wall_s, outcome (an Outcome's name),
    reason, err_estimate, estimate_force_evals,
    err_basis, warning; with ``scattering=True`` the encounter's (r_min, t_min, r_min_error, t_min_error,
    deflection, out_of_plane, b_in, v_inf_in, time_delay, asymptote_error, start_distance_error,
    time_delay_error (the time delay's total: the run's part and the start distance's), deflection_error, start_distance_force_evals, event_force_evals, K1_turn, spin_turn,
    K1x..K1z, asymptotes); then steps, t_end, vx..vz, wx..wz. One row per (grid point, method), grid point major.
    ``progress``: a line on stderr, rewritten as rows finish (rows done, elapsed, time left), for calls
    longer than a second; None (the default) shows it where stderr is a terminal or in a Jupyter
    notebook, not in a script whose stderr is a file or pipe, nor under CI; True or False decide.
    """
    automatic = any(name.strip() == "auto" for m in ([methods] if isinstance(methods, str) else methods)
                    for name in str(m).split(","))
    if steps == 0 and t_end == 0.0 and not (scattering and (accuracy is not None or automatic)):
        raise Error("give steps or t_end (an encounter in the accuracy mode runs to its departure without them)")
    try:
        axes = list(dict(axes).items())
    except (TypeError, ValueError):
        raise Error(f"axes must be a dict {{parameter: values}}, got {type(axes).__name__}") from None
    columns = [(_text("an axis' parameter", k), _numbers_of(f"the values of {k}", vals)) for k, vals in axes]
    toml = None
    if scene is not None:
        toml, columns, base, force_law = _sweep_scene(scene, columns, base, force_law)
    return _core._sweep(columns, _texts("methods", methods), base, _number("h", h), _count("steps", steps),
                        _number("t_end", t_end), _number("tol", tol),
                        0 if threads is None else _count("threads", threads), _number("max_energy_error", max_energy_error),
                        _flag("estimate_error", estimate_error), _number("max_error", max_error),
                        _flag("scattering", scattering),
                        _text("force_law", force_law), _number("accuracy", accuracy, optional=True),
                        _number("max_seconds", max_seconds), toml, _progress(progress, "sweep", "rows"))


def encounter(scene, *, t_end=None, method="auto", tol=1e-10, max_seconds=DEFAULT_MAX_SECONDS):
    """The first body's encounter in the accuracy mode (docs/physics.md, Scattering).

    Without t_end the run stops when the body has left (its guiding centre back at its start distance),
    at the latest after two free passes; with t_end it runs to t_end. Returns outcome ("ok", or
    "incomplete" when the run ended before the body left: then deflection, out_of_plane, b_in, v_inf_in and
    time_delay are None), reason, deflection, out_of_plane, b_in, v_inf_in (the incoming asymptote's
    impact parameter and speed at infinity, as measured: the sweep's columns of these names), b_in_error,
    v_inf_in_error (their asymptotes' model error), out_of_plane_error, time_delay, asymptote_error (the
    asymptotes' model error in the deflection; for B = 0 about one centre its formula's rounding) and
    asymptote_basis, start_distance_error (what the finite start distance L leaves in the deflection
    against L -> infinity: a spinning body's scene of thesis_scene() is run again from 2L, and given by b or
    v_inf its deflection, out_of_plane and time_delay are their values at that limit, 2 x(2L) - x(L); 0 for
    a material point and for a scene given by its states, whose observables are its trajectory's),
    time_delay_error (the time delay's total: time_delay_run_error, the run's estimate carried to the
    delay by its companion, and the start distance's part),
    start_distance_basis, start_distance_force_evals (the run from 2L, its far legs alone where it shares
    the run between them with this one's; in run's total_force_evals too),
    deflection_error (the deflection's total: the run's estimate, the asymptotes' and the start
    distance's; None where a part is not known), K1_turn, spin_turn,
    r_min, t_min (the closest approach to any centre), asymptotes, direction_in and direction_out, K1,
    K2 (and K2Q) and E at both ends: the keys of ``simulate --scattering --json``'s "scattering" object.
    ``run`` holds the run's own fields, as integrate() gives a body's (method, steps, t_end,
    err_estimate, force_evals, total_force_evals, events, ...).
    A run that is not ok (refused, diverged, ...) raises bodypoint.Error."""
    return _core._encounter(_scene(scene), _text("method", method), _number("tol", tol),
                            float("nan") if t_end is None else _number("t_end", t_end),
                            _number("max_seconds", max_seconds), getattr(scene, "_thesis", None))


class Stepper:
    """One body of a scene advanced segment by segment, as the library's Stepper (bodypoint.hpp).

        s = bp.Stepper(scene, "lp-kl8", 0.01, stop_at=["r=5"])
        s.advance_to(50)          # an Outcome; stops early at the first hit of a stop event
        s.stopped, s.time, s.state["R"], s.events
        s.advance_to(50)          # continues from the stop
        s.advance_to(0)           # backwards in time, to the start
        s = bp.Stepper(scene, "auto", tol=1e-10, t_end=50)   # the accuracy mode chooses method and step
        s.accuracy                # its search: tol, t_end, err_estimate (at t_end), h_chosen, basis

    ``step``: a fixed-step method's largest step (each segment lands on its end), the fictitious step
    ds of a time-transformed one, or a step-size-controlled peer's tolerance per step. Or ``tol`` with
    ``t_end``: the accuracy mode searches the method ("auto") or the named method's step for that span
    (a negative t_end: backwards) and the segments advance with what it delivered; ``accuracy`` gives
    the search and its estimate, which holds at t_end (landing on the segments' times only shortens
    steps). A time before ``time`` integrates backwards (time reversal; a symmetric splitting run
    forwards and back by the same steps returns to round-off). ``state`` can be set (a dict of R, v, w
    and optionally t); a Stepper made with ``tol`` then searches again from the state written, for the
    span to ``t_end`` (``accuracy`` its new search; the error the state carried in is not in it).
    One segment is integrate()'s run of the same steps bit for bit (``invariants`` tracked as there);
    segments land on their times with a shortened last step, so several segments differ from one run
    by round-off and that step's error. ab4 restarts its history at each segment.
    ``events`` / ``stop_at``: as integrate()'s, at absolute times. ``closest`` is the closest approach
    *so far*: a later segment that comes nearer replaces it (on table 3.1, after advance_to(28) a helix
    wiggle at t = 27.571, r = 10.76; after advance_to(28.5) the encounter's minimum, t = 28.399, r = 9.0546).
    A Stepper made with ``tol`` carries its error: a companion one level finer (h/2, ds/2) goes beside it
    through every segment and every write (taken as a change), and ``error`` is the chain's error at
    ``time``, forwards and back included; ``carry_error`` hands one Stepper's ``error`` to the next where
    runs are chained. One given a step has none. Ctrl-C or ``max_seconds`` stop the search of a Stepper
    made with ``tol`` as they stop a segment (KeyboardInterrupt, or bodypoint.Error for the budget).
    """

    def __init__(self, scene, method="auto", step=None, *, tol=None, t_end=None, body=0, events=(), stop_at=(),
                 omega_c=None, invariants=True, max_seconds=DEFAULT_MAX_SECONDS):
        self._s = _core._Stepper(_scene(scene), _index("body", body), _text("method", method),
                                 _number("step", step, optional=True), _texts("events", events),
                                 _texts("stop_at", stop_at), _number("omega_c", omega_c, optional=True),
                                 _number("tol", tol, optional=True), _number("t_end", t_end, optional=True),
                                 _flag("invariants", invariants), _number("max_seconds", max_seconds))

    def advance_to(self, t, *, max_seconds=DEFAULT_MAX_SECONDS):
        """Integrates from time to t (before time: backwards); returns the segment's Outcome (refused or
        failed leave the stepper where it was: ``reason`` says why). Ctrl-C or max_seconds stop the
        segment (the stepper stays where it was) and raise KeyboardInterrupt or bodypoint.Error."""
        return Outcome(self._s.advance_to(_number("t", t), _number("max_seconds", max_seconds)))

    def _set_state(self, state):
        if not isinstance(state, dict):
            raise Error(f"state must be a dict of R, v, w (and t), got {type(state).__name__}")
        self._s.state = state

    time = property(lambda self: self._s.time, doc="the current time")
    state = property(lambda self: self._s.state, _set_state,
                     doc="the current state: t, R, v, w; set it with a dict of some of them (checked as a scene's)")
    accuracy = property(lambda self: self._s.accuracy,
                        doc="with tol: the search (tol, t_end, h_chosen, basis, force_evals), made again after a write "
                            "that moves a time scale; err_estimate is the search's (at t_end) until a segment ran, then "
                            "the chain's at time (as error); else None")
    error = property(lambda self: self._s.error,
                     doc="the estimated error at time: t, estimate (relative, of R and v; None where there is none), "
                         "basis, R, v, w (the state less the true one, estimated) and the companion's force_evals")

    def apply(self, write):
        """Writes the state by a map: ``write`` takes a state dict (t, R, v, w) and returns a dict of the
        entries it writes; it is applied to the state and to the companion's, so that the error carried
        turns with the write. ``s.state = {...}`` scales the companion's R, v or w where the write scaled
        them (w = -w) and moves them by the same change otherwise (a kick)."""
        if not callable(write):
            raise Error(f"write must be a function of the state, got {type(write).__name__}")
        self._s.apply(write)

    def carry_error(self, error):
        """Carries an error into the current state: a dict of R, v, w (another Stepper's ``error``), so that
        a chain of separate Steppers reports the chain's error. Needs a Stepper made with ``tol``."""
        if not isinstance(error, dict):
            raise Error(f"error must be a dict of R, v, w, got {type(error).__name__}")
        self._s.carry_error(error)
    step = property(lambda self: self._s.step, doc="the segments' step (h, ds, or a tolerance per step)")
    events = property(lambda self: self._s.events, doc="events located so far: event, t, r, R, v, w")
    stopped = property(lambda self: self._s.stopped, doc="a stop event ended the last segment")
    force_evals = property(lambda self: self._s.force_evals, doc="force evaluations so far")
    steps = property(lambda self: self._s.steps, doc="steps so far")
    reason = property(lambda self: self._s.reason, doc="why the last segment that was not ok was not")
    method = property(lambda self: self._s.method, doc="the method's name")

    def __repr__(self):
        return f"<bodypoint.Stepper {self.method} at t = {self.time!r}>"
