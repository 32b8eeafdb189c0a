"""pwl: dynamics of piecewise-linear structures (gap-activated springs), from Python.

Every job of the pwl program is a function here, with the program's flags as keyword arguments,
dashes written as underscores (``--skip-periods 10`` is ``skip_periods=10``); the names, defaults,
checks and error messages are the program's own, since the module parses the keywords with the
program's flag definitions. ``help(pwl.simulate)`` (or ``pwl <job> --help``) lists every keyword
with its default and meaning. Values are Python values: numbers, strings, True for a flag that is
given (``locate_kinks=True``), a list, tuple or NumPy array for a list of values (``loads=[1, -1, 1,
-1, 1]``, ``x0=np.zeros(5)``), a pair for a range (``range=(0.5, 3)``, ``x_range=(0.5, 3)``), and a
``Structure`` wherever a structure goes (``structure=S``, or ``structure_scene=S``); the command
line's strings keep working (``range="0.5:3"``, ``loads="1,-1,1,-1,1"``). None leaves a flag out.
The flags that only shape the program's files or printout (``out``, ``quiet``, ``no_plot``, ...)
are not taken: the functions return NumPy arrays instead and write nothing. Every result prints
as one line that says what it holds (``repr``).

    simulate(**flags)   -> SimulateResult      pwl simulate
    analyze(**flags)    -> AnalyzeResult       pwl analyze
    sweep(**flags)      -> SweepResult         pwl sweep
    map(**flags)        -> MapResult           pwl map
    orbit(**flags)      -> OrbitResult         pwl orbit
    continue_(**flags)  -> ContinuationResult  pwl continue (also named continuation)

Any job takes ``structure=Structure(M, C, K, springs=[...], loads=[...])`` in place of the chain's
flags (figure, n, alpha, zeta, gap, gaps, theta, loads), as the program takes --structure-scene.

Errors: InputError (a ValueError) for bad input, with the program's message; RunError (a
RuntimeError) for a run that failed (an unsolvable contact problem, a blow-up, Newton that did
not converge); TypeError for a keyword that is not a flag of the job.

The jobs release the GIL while they integrate, so other Python threads run meanwhile. Ctrl-C
stops simulate, analyze, sweep, map and continue_ within about 0.2 s (KeyboardInterrupt); orbit
stops when its Newton iterations end.
"""

import numpy as _np

from . import _pwl
from ._pwl import InputError, RunError, Structure, __version__

__all__ = [
    "simulate", "analyze", "sweep", "map", "orbit", "continue_", "continuation", "Structure",
    "InputError", "RunError", "SimulateResult", "AnalyzeResult", "SweepResult", "MapResult",
    "OrbitResult", "ContinuationResult", "__version__",
]


def _text(values):
    """A list of str as a NumPy array of str (keeps its length when empty)."""
    return _np.array(values, dtype=str)


def _counts(labels):
    """'12 period-1, 3 chaotic': how many of each label, most frequent first."""
    values, counts = _np.unique(_np.asarray(labels, dtype=str), return_counts=True)
    order = _np.argsort(-counts, kind="stable")
    return ", ".join("{} {}".format(counts[i], values[i]) for i in order)


class _Result:
    """A job's answer: its fields as attributes; ``fields()`` lists them."""

    def __init__(self, fields):
        self.__dict__.update(fields)

    def _summary(self):
        return ""

    def __repr__(self):
        return "{}({})".format(type(self).__name__, self._summary())

    def fields(self):
        """The result's fields, one per line, with the shape of each array."""
        def short(value):
            if isinstance(value, _np.ndarray):
                return "array(shape={}, dtype={})".format(value.shape, value.dtype)
            if isinstance(value, dict):
                return "{" + ", ".join(sorted(value)) + "}"
            text = repr(value)
            return text if len(text) <= 60 else text[:57] + "..."
        return "\n".join("{} = {}".format(k, short(v)) for k, v in self.__dict__.items())


class SimulateResult(_Result):
    """One case integrated (pwl simulate).

    poincare: (points, 2n) the rows of poincare.csv without their time: x1..xn, v1..vn at every
        point of the section (t = kT by default, the initial state first when nothing is skipped)
    t: (points,) their times
    columns: the names of poincare's columns
    trajectory, trajectory_t, trajectory_columns: with record=[masses], the rows of
        trajectory.csv without their time (x of each recorded mass, then v of each), their
        times and names; None otherwise
    record: the recorded masses (1-based)
    integrator, method: the integrator's description and the method's name
    stats: steps, rejected_steps, rhs_evaluations, kink_events, lcp_pivots
    dofs, forcing_period, section, description: the case
    """

    def _summary(self):
        return "{}: {} section points of {} components by {}, t from {:g} to {:g}".format(
            self.description, len(self.t), self.poincare.shape[1], self.method,
            self.t[0] if len(self.t) else 0.0, self.t[-1] if len(self.t) else 0.0)


class AnalyzeResult(_Result):
    """One case classified, with its evidence (pwl analyze).

    regime: "period-2", "quasi-periodic", "chaotic", "unbounded", "uncertain", ...
    code: the regime's number in maps and legends; period: k of a period-k motion, else 0
    lambda1, lambda1_error: the largest Lyapunov exponent per forcing period and its error
    K: the 0-1 test (NaN when not computed); zero_one_source: what it was computed from
    period_search: the period search (period, fixed_point, mismatch, best_k, distinct_points,
        scale, diameter, points_used); None for an unbounded or failed motion
    reason: the rule that decided, with its numbers
    poincare, t, period_index, columns: the recorded section points (poincare.csv's rows
        without the time), their times and periods
    final_state: [x; v] after the record; lyapunov: how lambda1 was estimated
    transient, recorded, mass, dofs, forcing_period, integrator, method, section, description
    The evidence ladder's steps (on unless quick=True), as the columns of pwl sweep and map:
    minimal_period, multiplier, settle_periods and record_period (Newton's check of a period),
    decided_by, confirmed_by and confirmation (the method the verdict rests on and how it was
    checked), observed_periods, extra_periods, halves and rotation_pq (what it was seen over),
    torus_digits, rotation, chaotic_transient, disagreement; seconds: what the evaluation cost
    """

    def _summary(self):
        return "{}, lambda1 = {:.4g} +- {:.2g}, K = {:.3g}; {} by {}, decided by {}".format(
            self.regime, self.lambda1, self.lambda1_error, self.K, self.description, self.method,
            self.decided_by)


class SweepResult(_Result):
    """A one-parameter sweep (pwl sweep).

    parameter: the swept parameter's name; values: its N values; points: N; mode
    poincare: (rows, components) every recorded Poincaré point, in poincare.csv's order (upward
        points first, then downward, each by index), with poincare_parameter, poincare_direction
        ("up"/"down"), poincare_index, and poincare_period (t = kT sections) or poincare_t
        (hyperplane sections) beside them; components: their names ("x5", "v5")
    table: classification.csv as a dict of columns (index, <parameter>, direction, regime, code,
        period, lambda1, lambda1_error, K, ...): one row per value and direction
    regime, code, period, lambda1, lambda1_error, K: the same columns, as attributes
    section, description: the sweep's section and its settings (config.txt)
    points_of(index, direction="up"): the Poincaré points of one value
    """

    def _summary(self):
        return "{} from {:g} to {:g}, {} values ({}): {}".format(
            self.parameter, self.values[0], self.values[-1], self.points, self.mode,
            _counts(self.regime))

    def __init__(self, fields):
        for key in ("poincare_direction", "components"):
            fields[key] = _text(fields[key])
        fields["table"] = {k: _text(v) if isinstance(v, list) else v
                           for k, v in fields["table"].items()}
        super().__init__(fields)
        for name, column in self.table.items():
            if name not in ("index", "direction", self.parameter):
                setattr(self, name, column)

    def points_of(self, index, direction="up"):
        """The recorded Poincaré points (rows, components) of value `index` (0-based, at
        values[index]) in `direction` ("up", or "down" for a continuation's downward branch)."""
        chosen = (self.poincare_index == index) & (self.poincare_direction == direction)
        return self.poincare[chosen]


class MapResult(_Result):
    """A two-parameter regime map (pwl map).

    x, y: the two parameters' names; x_values, y_values: their values
    table: map.csv as a dict of columns (i, j, <x>, <y>, regime, code, period, lambda1,
        lambda1_error, K, ...), one row per cell, j then i
    regime, code, period, lambda1, lambda1_error, K: the same as grids, shape
        (len(y_values), len(x_values)): row j is y_values[j], column i is x_values[i]
    mode, description: the map's settings (config.txt)
    """

    def _summary(self):
        return "{} x {}, {} x {} cells: {}".format(
            self.x, self.y, len(self.x_values), len(self.y_values), _counts(self.regime.ravel()))

    def __init__(self, fields):
        fields["table"] = {k: _text(v) if isinstance(v, list) else v
                           for k, v in fields["table"].items()}
        super().__init__(fields)
        shape = (len(self.y_values), len(self.x_values))
        for name, column in self.table.items():
            if name not in ("i", "j", self.x, self.y):
                setattr(self, name, _np.ascontiguousarray(column.reshape(shape)))


class OrbitResult(_Result):
    """A periodic orbit by shooting (pwl orbit).

    state: [x; v] at t = 0 mod T (orbit.csv); period: k; forcing_period: T
    minimal_period: the smallest m dividing k whose map closes the orbit (m < k: the orbit found
        is the period-m orbit taken k/m times); minimal_largest_modulus: its largest |mu| at m
    multipliers: the Floquet multipliers, complex, largest modulus first (floquet.csv);
        multipliers_complete: all of them (else Arnoldi's leading ones); largest_modulus
    stable: every multiplier inside the unit circle; verdict: "stable" or "unstable";
        unstable_count: multipliers outside it
    residual, iterations, evaluations, solver, exact_tangent, krylov_products, preconditioned:
        Newton's numbers; monodromy: the monodromy matrix (dense solver; else None)
    amplitude, max_position, min_position: max |x_i|, max x_i, min x_i over the orbit;
        max_gap, min_gap: the extremes of every gap function
    method, method_default, description
    """

    def _summary(self):
        minimal = ("" if self.minimal_period == self.period else
                   " (minimal period {})".format(self.minimal_period))
        return "period-{} orbit{}, {}, largest |mu| {:.6g}, residual {:.2g}; {}".format(
            self.period, minimal, self.verdict, self.largest_modulus, self.residual,
            self.description)


class ContinuationResult(_Result):
    """A periodic orbit followed in one parameter (pwl continue).

    One row per branch point, in the order computed (branch.csv): branch, parameter, arclength,
    period, stable (bool), max_abs_multiplier, unstable_multipliers, residual, iterations,
    amplitude (points, n), state (points, 2n), multipliers (points, 2n) complex, largest first.
    bifurcations: bifurcations.csv as a dict of columns: type ("fold", "period-doubling",
        "neimark-sacker", "grazing"), parameter, branch, period, spring (1-based, 0 for none),
        multiplier (complex, NaN for a grazing), abs_multiplier, detail, located, at_largest_gap,
        to_branch, joined_by (-1 for none), test_value, state (bifurcations, 2n)
    notes: why each branch stopped
    work: the continuation's counts as a dict: matrix_free (bool), monodromies, integrations,
        krylov_products (GMRES), multiplier_products, unconverged_multipliers, uncovered_bands
        (points whose multipliers stopped short of the margin's band), davidson_points and
        arnoldi_points (matrix-free points whose multipliers came from Davidson's method
        preconditioned by the open structure, or from Arnoldi), band_cuts (steps halved by
        the band round the circle), band (the band asked; matrix-free widened to the margin),
        narrowest_band (the narrowest band a step was checked in:
        narrower than asked where only the leading multipliers were known; inf: none checked),
        step_cuts
    curves (with curves=(Q, (FROM, TO))): curves.csv as a dict of columns: curve, type, the two
        parameters by name, period, spring (1-based, 0 for none), multiplier (complex), kappa,
        amplitude (rows, n), state (rows, 2n); None without curves=
    codim2: codim2.csv as a dict of columns: type, the two parameters by name, curves (the curves
        each point was found on), detail, state; None without curves=
    curve_ends: for each curve, why it ended each way; curve_notes: the curves' notes
    curve_work: the curves' counts as a dict: monodromies, integrations, krylov_products,
        multiplier_products, unconverged_multipliers, uncovered_bands, davidson_points,
        arnoldi_points (as work's); None without curves=
    parameter_name, method, method_default, description
    """

    def _summary(self):
        kinds = _counts(self.bifurcations["type"]) if len(self.bifurcations["type"]) else "none"
        text = "{}: {} points on {} branch(es), {} stable; bifurcations: {}".format(
            self.parameter_name, len(self.parameter), len(_np.unique(self.branch)),
            int(_np.sum(self.stable)), kinds)
        if self.curves is not None:
            text += "; {} curve(s), {} points, {} codimension-two point(s)".format(
                len(self.curve_ends), len(self.curves["curve"]), len(self.codim2["type"]))
        return text

    def __init__(self, fields):
        fields["stable"] = fields["stable"].astype(bool)
        table = fields["bifurcations"]
        for key in ("type", "detail"):
            table[key] = _text(table[key])
        for key in ("located", "at_largest_gap"):
            table[key] = table[key].astype(bool)
        for name in ("curves", "codim2"):
            if fields.get(name) is not None:
                fields[name]["type"] = _text(fields[name]["type"])
        if fields.get("codim2") is not None:
            fields["codim2"]["detail"] = _text(fields["codim2"]["detail"])
        super().__init__(fields)


def simulate(**flags):
    """Integrate one case (the flags of ``pwl simulate``); returns a SimulateResult.

    >>> r = pwl.simulate(figure="4a", periods=20, record=[5])
    >>> r.poincare.shape, r.trajectory.shape
    ((21, 10), (4000, 2))
    """
    return SimulateResult(_pwl.simulate(**flags))


def analyze(**flags):
    """Classify the motion of one case (the flags of ``pwl analyze``); returns an AnalyzeResult."""
    return AnalyzeResult(_pwl.analyze(**flags))


def sweep(**flags):
    """A bifurcation diagram's data (the flags of ``pwl sweep``); returns a SweepResult."""
    return SweepResult(_pwl.sweep(**flags))


def map(**flags):  # noqa: A001 (pwl map's name)
    """A regime map over two parameters (the flags of ``pwl map``); returns a MapResult."""
    return MapResult(_pwl.map(**flags))


def orbit(**flags):
    """A periodic orbit by shooting (the flags of ``pwl orbit``); returns an OrbitResult."""
    return OrbitResult(_pwl.orbit(**flags))


def continue_(**flags):
    """Follow a periodic orbit in one parameter (the flags of ``pwl continue``; ``continue`` is a
    Python keyword); returns a ContinuationResult."""
    return ContinuationResult(_pwl.continue_(**flags))


continuation = continue_


def _document(function, job):
    """Appends the job's keywords (the program's flags it takes) to `function`'s docstring, each
    with its default and meaning, so that help(pwl.JOB) lists them."""
    lines = ["", "Keyword arguments (the flags of ``pwl {}``; None leaves one out):".format(
        job.rstrip("_")), ""]
    lines.append("structure : Structure, default None")
    lines.append("    An explicit structure in place of the chain's keywords (figure, n, alpha,")
    lines.append("    zeta, gap, gaps, theta, loads); also accepted as structure_scene.")
    for keyword, default, description, flag in _pwl.keywords(job):
        kind = "bool" if flag else "value"
        shown = default if default != "" else "none"
        lines.append("{} : {}, default {}".format(keyword, kind, shown))
        for line in description.splitlines():
            lines.append("    " + line)
    function.__doc__ = (function.__doc__ or "") + "\n" + "\n".join(lines) + "\n"


for _function, _job in ((simulate, "simulate"), (analyze, "analyze"), (sweep, "sweep"),
                        (map, "map"), (orbit, "orbit"), (continue_, "continue_")):
    _document(_function, _job)
del _function, _job
