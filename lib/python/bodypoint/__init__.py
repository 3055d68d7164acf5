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
from ._bodypoint import Error, Scene
from . import _bodypoint as _core

__all__ = ["Error", "Scene", "methods", "scene_parameters", "thesis_scene", "read_scene", "parse_scene",
           "integrate", "trajectory", "sweep", "encounter"]


def methods():
    """Every method of the catalogue: dicts with name, family, order, stages, evals_per_step, description."""
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
    return _core._thesis_scene(params)


def read_scene(path):
    """A scene from a TOML scene file (the project's scenes/ folder has examples)."""
    return _core._read_scene(str(path))


def parse_scene(text):
    """A scene from the text of a TOML scene file."""
    return _core._parse_scene(text)


def integrate(scene, method="auto", *, h=None, steps=None, t_end=None, tol=None, invariants=True,
              omega_c=-1.0, events=(), max_energy_error=_core.DEFAULT_MAX_ENERGY_ERROR, estimate_error=True,
              max_error=_core.DEFAULT_MAX_ERROR):
    """Integrates every body of the scene; returns a dict (outcome, reason, force_evals, wall_s, bodies).

    How time advances follows the method's kind, as on the command line:
      fixed-step methods: steps of h (``steps`` of them, or to ``t_end`` exactly with the largest
          step <= h that lands on it);
      time-transformed methods (logh-*, ttl-*, ks): fictitious step ds = h, to t_end exactly or
          ``steps`` fictitious steps;
      step-size-controlled peers (odeint-*, gsl-*): ``tol`` per step to t_end, first trial step h;
      ``tol`` with any other method, or method "auto": the accuracy mode, the final state's relative
          error at most tol at t_end (the step, and for "auto" the method, are chosen).
    Each body's dict has its name and the keys of ``bodypoint simulate --json`` (docs/guide.md, "Output
    fields"): method, outcome, reason, h, the final R, v, w (numpy arrays), t_end, steps, the invariants'
    largest deviations (max_rel_dE, max_rel_dK2sq, max_abs_dK2Q), force_evals (the delivered run's),
    total_force_evals (with the accuracy mode's search, the error estimate and the events), the
    accuracy mode's search (tol, h_chosen, search_runs, search_force_evals) and its choice (chosen),
    and the events asked for (the forms of the command line's --event), located on the method's own
    steps: events (event, t, r, R, v, w), event_force_evals.
    Each body's ``err_estimate`` is the estimated relative error of its final state, max(|dR|/|R|,
    |dv|/|v|): from a companion run at half the step (a tenth of a peer's tolerance; it costs about twice
    the run), or the accuracy mode's; None when there is none, ``err_basis`` saying how it was obtained
    or why there is none (``estimate_error=False``: not asked for). ``warnings``: flags the estimate
    overruled.
    The outcome is "ok", or the flag of a run whose numbers bodypoint does not vouch for: "diverged",
    "unresolved" (a step too large for the spin or the encounter), "inaccurate" (an energy error above
    ``max_energy_error``, or an estimated error above ``max_error``; float("inf") lifts a bound),
    "collision"; or "refused"/"failed" without a run (docs/physics.md, "Resolution and accuracy flags").
    """
    return _core._integrate(scene, method, h, steps, t_end, tol, invariants, omega_c, list(events),
                            float(max_energy_error), bool(estimate_error), float(max_error))


def trajectory(scene, method, step, times, *, omega_c=-1.0):
    """Each body's state at the given times (increasing, >= 0): a list of dicts with t (n,) and R, v, w
    (n, 3) numpy arrays. ``step``: the step h of a fixed-step method (the largest step <= h that lands on
    every requested time), the fictitious step ds of a time-transformed one, or the tolerance per step
    of a step-size-controlled peer."""
    return _core._trajectory(scene, method, float(step), [float(t) for t in times], omega_c)


def sweep(axes, methods, *, h=1e-4, steps=0, t_end=0.0, tol=1e-10, threads=1, max_energy_error=_core.DEFAULT_MAX_ENERGY_ERROR,
          estimate_error=True, max_error=_core.DEFAULT_MAX_ERROR, **base):
    """Runs the thesis's scene over a grid of parameters and methods; returns columns.

    ``axes``: {parameter: values} in order (one axis, or a grid of every combination, the last axis
    fastest); a parameter is h, one of scene_parameters(), b or v_inf. ``methods``: names.
    ``base``: fixed scene parameters. Steps of h: ``steps`` of them, or to ``t_end``. The result has a
    column per axis, method, outcome, reason, steps, force_evals, t_end, Rx..wz and the invariants'
    deviations, err_estimate and err_basis (integrate()'s), one row per (grid point, method), grid point
    major; outcome as integrate()'s, with the bounds ``max_energy_error`` and ``max_error``.
    """
    if isinstance(methods, str):
        methods = [methods]
    if not steps and not t_end:
        raise Error("give steps or t_end")
    return _core._sweep([(k, [float(v) for v in vals]) for k, vals in dict(axes).items()], list(methods), base,
                        float(h), int(steps), float(t_end), float(tol), int(threads), float(max_energy_error),
                        bool(estimate_error), float(max_error))


def encounter(scene, *, t_end=None, method="auto", tol=1e-10):
    """The first body's encounter in the accuracy mode (docs/physics.md, Scattering).

    Without t_end the run stops when the body has left (its guiding centre back at its start distance),
    at the latest after two free passes; with t_end it runs to t_end. Returns outcome ("ok", or
    "incomplete" when the run ended before the body left: then deflection, out_of_plane, b, v_inf and
    time_delay are None), reason, deflection, out_of_plane, b, v_inf, time_delay, asymptote_error (the
    asymptotes' model error in the deflection; 0 for B = 0) and asymptote_basis, K1_turn, spin_turn,
    r_min, t_min (the closest approach to any centre), asymptotes, direction_in and direction_out, K1,
    K2 (and K2Q) and E at both ends: the keys of ``simulate --scattering --json``'s "scattering" object.
    ``run`` holds the run's own fields, as integrate() gives a body's (method, steps, t_end,
    err_estimate, force_evals, total_force_evals, events, ...).
    A run that is not ok (refused, diverged, ...) raises bodypoint.Error."""
    return _core._encounter(scene, method, tol, float("nan") if t_end is None else t_end)
