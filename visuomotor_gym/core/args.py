"""Constructor-argument checks shared by every env: each error names the argument, the value it got
and what is allowed (Gymnasium users meet these first, before any physics runs)."""

from __future__ import annotations

import math
from dataclasses import MISSING, dataclass, fields
from numbers import Integral, Real
from typing import Any


def choice(value: Any, allowed, arg_name: str):
    """``value`` if it is one of ``allowed``, else ``ValueError`` listing the allowed values."""
    if (isinstance(value, str) or value is None) and value in allowed:
        return value
    raise ValueError(f"{arg_name}={value!r} is not one of {list(allowed)}")


def flag(value: Any, arg_name: str) -> bool:
    """A real boolean (``True``/``False``, numpy bools included): strings such as ``"no"`` are refused,
    since ``bool("no")`` is True."""
    if isinstance(value, bool) or type(value).__name__ == "bool_":
        return bool(value)
    raise TypeError(f"{arg_name} must be True or False, got {value!r} ({type(value).__name__})")


def real(
    value: Any,
    arg_name: str,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    high_open: bool = False,
) -> float:
    """A finite real number inside ``[low, high]`` (ends open where asked), as ``float``."""
    if isinstance(value, bool) or not isinstance(value, Real):
        raise TypeError(f"{arg_name} must be a real number, got {value!r} ({type(value).__name__})")
    x = float(value)
    lo_txt = "-inf" if low is None else f"{low:g}"
    hi_txt = "inf" if high is None else f"{high:g}"
    allowed = f"{'(' if low_open else '['}{lo_txt}, {hi_txt}{')' if high_open else ']'}"
    if not math.isfinite(x):
        where = f", in {allowed}" if (low is not None or high is not None) else ""
        raise ValueError(f"{arg_name} must be a finite number{where}; got {value!r}")
    if low is not None and (x < low or (low_open and x == low)):
        raise ValueError(f"{arg_name} must be in {allowed}; got {value!r}")
    if high is not None and (x > high or (high_open and x == high)):
        raise ValueError(f"{arg_name} must be in {allowed}; got {value!r}")
    return x


def integer(value: Any, arg_name: str, *, low: int | None = None, high: int | None = None) -> int:
    """An integer (not a bool, not a float) inside ``[low, high]``."""
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise TypeError(f"{arg_name} must be an integer, got {value!r} ({type(value).__name__})")
    n = int(value)
    if (low is not None and n < low) or (high is not None and n > high):
        raise ValueError(f"{arg_name} must be an integer in [{low}, {high}]; got {value!r}")
    return n


def coerce(cls, value: Any, arg_name: str):
    """Accept a params dataclass, a dict of its fields, or None (defaults). A field its class refuses
    (:func:`check_fields`) is reported as ``<arg_name>.<field>``."""
    if value is None:
        return cls()
    if isinstance(value, cls):
        return value
    if isinstance(value, dict):
        allowed = {f.name for f in fields(cls)}
        unknown = sorted(set(value) - allowed)
        if unknown:
            raise TypeError(f"{arg_name}: unknown field(s) {unknown}; allowed: {sorted(allowed)}")
        try:
            return cls(**value)
        except ParamValueError as exc:
            raise ParamValueError(arg_name, exc.detail) from None
        except ParamTypeError as exc:
            raise ParamTypeError(arg_name, exc.detail) from None
    raise TypeError(f"{arg_name} must be a {cls.__name__}, a dict of its fields or None; got {type(value).__name__}")


def whole_multiple(value: float, unit: float, arg_name: str, *, minimum: int = 0) -> int:
    """``value / unit`` when it is a whole number >= ``minimum`` (to 1e-9), else ``ValueError``."""
    ratio = value / unit
    if not (abs(ratio - round(ratio)) < 1e-9 and round(ratio) >= minimum):
        least = "a positive" if minimum >= 1 else "a non-negative"
        raise ValueError(f"{arg_name}={value!r} must be {least} whole multiple of {unit!r} s")
    return int(round(ratio))


# ----------------------------------------------------------------------------------------------
# Parameter dataclasses (GaitParams, the course, crowd and throw distributions, VisionParams,
# OculomotorParams, HandControlParams...): every field checked at construction against a declared
# rule, so that a bad value is refused with the argument's and the field's name before any physics
# runs (and MuJoCo never logs a NaN state into the user's folder). A class declares its rules in a
# dict and calls :func:`check_fields` from ``__post_init__``; a field without a declared rule still
# gets the check its default's type implies (finite numbers, real booleans), so a field added later
# is never unchecked. The bounds themselves are modelling choices (what the models were built and
# tested for) unless the module that declares them cites a source.
# ----------------------------------------------------------------------------------------------
class ParamValueError(ValueError):
    """A field of a parameter dataclass out of its rule: ``<owner>.<field> must be ...``. ``owner`` is
    the class name, or the constructor argument's name once :func:`coerce` has re-raised it."""

    def __init__(self, owner: str, detail: str | None = None) -> None:
        # One argument: a whole message (Gymnasium's make re-raises a TypeError as type(e)(message)).
        self.owner, self.detail = (owner, detail) if detail is not None else ("", owner)
        super().__init__(f"{owner}.{detail}" if detail is not None else owner)


class ParamTypeError(TypeError):
    """As :class:`ParamValueError`, for a value of the wrong type."""

    def __init__(self, owner: str, detail: str | None = None) -> None:
        # One argument: a whole message (Gymnasium's make re-raises a TypeError as type(e)(message)).
        self.owner, self.detail = (owner, detail) if detail is not None else ("", owner)
        super().__init__(f"{owner}.{detail}" if detail is not None else owner)


@dataclass(frozen=True)
class Num:
    """A finite real number in ``[low, high]`` (ends open where asked; ``None``: unbounded on that side).
    ``inf_ok``: ``+inf`` is a documented value (e.g. "no limit")."""

    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    inf_ok: bool = False

    def __call__(self, value: Any, name: str) -> Any:
        if self.inf_ok and not isinstance(value, bool) and isinstance(value, Real) and value == math.inf:
            return value
        real(value, name, low=self.low, high=self.high, low_open=self.low_open, high_open=self.high_open)
        return value

    def describe(self) -> str:
        lo = "-inf" if self.low is None else f"{self.low:g}"
        hi = "inf" if self.high is None else f"{self.high:g}"
        return f"{'(' if self.low_open else '['}{lo}, {hi}{')' if self.high_open else ']'}"


@dataclass(frozen=True)
class Int:
    """An integer (not a bool) in ``[low, high]``."""

    low: int | None = None
    high: int | None = None

    def __call__(self, value: Any, name: str) -> Any:
        return integer(value, name, low=self.low, high=self.high)


@dataclass(frozen=True)
class Pair:
    """A ``(low, high)`` range: two finite numbers, each inside ``bounds`` (a :class:`Num`), with
    ``low <= high`` (``low < high`` when ``strict``; ``high - low >= min_width`` when given). Lists and
    arrays become tuples of floats."""

    bounds: Num = Num()
    strict: bool = False
    min_width: float = 0.0

    def __call__(self, value: Any, name: str) -> tuple[float, float]:
        pair = _sequence(value, name, 2, "(low, high) pair")
        lo, hi = (_element(v, name, self.bounds, value) for v in pair)
        if lo > hi or (self.strict and lo == hi):
            raise ValueError(f"{name} must be a (low, high) pair with low {'<' if self.strict else '<='} high; "
                             f"got {value!r}")
        if hi - lo < self.min_width:
            raise ValueError(f"{name} must be a (low, high) pair with high - low >= {self.min_width:g}; got {value!r}")
        return (lo, hi)


@dataclass(frozen=True)
class Weights:
    """``n`` relative probabilities: each in [0, 1], their sum > 0 (they are normalised by it)."""

    n: int

    def __call__(self, value: Any, name: str) -> tuple[float, ...]:
        items = _sequence(value, name, self.n, f"tuple of {self.n} probabilities")
        out = tuple(_element(v, name, Num(0.0, 1.0), value) for v in items)
        if not sum(out) > 0.0:
            raise ValueError(f"{name} must have a positive sum (the weights are normalised by it); got {value!r}")
        return out


@dataclass(frozen=True)
class Many:
    """``n`` finite numbers, each inside ``bounds``."""

    n: int
    bounds: Num = Num()

    def __call__(self, value: Any, name: str) -> tuple[float, ...]:
        items = _sequence(value, name, self.n, f"tuple of {self.n} numbers")
        return tuple(_element(v, name, self.bounds, value) for v in items)


class Flag:
    """A real boolean (see :func:`flag`)."""

    def __call__(self, value: Any, name: str) -> bool:
        return flag(value, name)


def _sequence(value: Any, name: str, n: int, what: str) -> list:
    if isinstance(value, (str, bytes, dict)) or not hasattr(value, "__len__") or not hasattr(value, "__iter__"):
        raise TypeError(f"{name} must be a {what}, got {value!r} ({type(value).__name__})")
    items = list(value)
    if len(items) != n:
        raise ValueError(f"{name} must be a {what}; got {len(items)} value(s): {value!r}")
    return items


def _element(v: Any, name: str, bounds: Num, whole: Any) -> float:
    if isinstance(v, bool) or not isinstance(v, Real):
        raise TypeError(f"{name} must hold real numbers, got {whole!r}")
    x = float(v)
    if not math.isfinite(x) or (bounds.low is not None and (x < bounds.low or (bounds.low_open and x == bounds.low))) \
            or (bounds.high is not None and (x > bounds.high or (bounds.high_open and x == bounds.high))):
        raise ValueError(f"{name} must hold finite numbers in {bounds.describe()}; got {whole!r}")
    return x


@dataclass(frozen=True)
class Optional:
    """``None`` (a mechanism off) or a value the inner rule accepts."""

    rule: Any

    def __call__(self, value: Any, name: str) -> Any:
        return None if value is None else self.rule(value, name)


@dataclass(frozen=True)
class Choice:
    """One of the allowed strings (see :func:`choice`)."""

    allowed: tuple

    def __call__(self, value: Any, name: str) -> Any:
        return choice(value, self.allowed, name)


def _default(f, value: Any) -> Any:
    """The field's default (its type decides the implied rule), or ``value`` when it has none."""
    if f.default is not MISSING:
        return f.default
    if f.default_factory is not MISSING:
        return f.default_factory()
    return value


def field_rule(f, rules: dict, default: Any):
    """The rule of dataclass field ``f``: its entry in ``rules``; else one its metadata declares
    (``"bounds": (low, high)`` with ``"low_open"`` and ``"optional"``, or ``"choices"``); else the one the
    type of its ``default`` implies (None: nothing to check, e.g. a string without choices)."""
    if f.name in rules:
        return rules[f.name]
    meta = f.metadata
    if "bounds" in meta:
        low, high = meta["bounds"]
        rule = Num(low, high, low_open=bool(meta.get("low_open", False)))
        return Optional(rule) if meta.get("optional") else rule
    if "choices" in meta:
        return Choice(tuple(meta["choices"]))
    return _implied_rule(default)


def _implied_rule(value: Any):
    """The check a field without a declared rule gets, from its value's type (None: no check)."""
    if isinstance(value, bool) or type(value).__name__ == "bool_":
        return Flag()
    if isinstance(value, Real):
        return Num()
    if isinstance(value, tuple) and value and all(isinstance(v, Real) and not isinstance(v, bool) for v in value):
        n = len(value)

        def finite_tuple(v, name):
            items = _sequence(v, name, n, f"tuple of {n} numbers")
            return tuple(_element(x, name, Num(), v) for x in items)

        return finite_tuple
    return None


def _field_value(obj: Any, spec: str) -> Any:
    """``obj.name`` for ``"name"``, ``obj.name[i]`` for ``"name[i]"``."""
    name, bracket, index = spec.partition("[")
    value = getattr(obj, name)
    return value[int(index.rstrip("]"))] if bracket else value


_ORDER_OPS = {"<": lambda a, b: a < b, "<=": lambda a, b: a <= b}


def check_fields(obj: Any, rules: dict, order: tuple = ()) -> None:
    """Check every field of the dataclass instance ``obj`` (call it from ``__post_init__``).

    ``rules``: field name -> rule (:class:`Num`, :class:`Int`, :class:`Pair`, :class:`Many`,
    :class:`Weights`, :class:`Flag`, or any ``rule(value, name) -> value`` raising ValueError/TypeError); fields not in it
    get the rule their metadata declares or their value's type implies (:func:`field_rule`). Sequences are
    stored back as tuples of floats.
    ``order``: ``(a, op, b)`` relations between fields, ``op`` one of ``<``, ``<=`` (numbers) or
    ``in`` (number ``a`` inside the range field ``b``); ``"name[i]"`` names an element of a range.
    Raises :class:`ParamValueError` / :class:`ParamTypeError` naming ``<Class>.<field>``.
    """
    owner = type(obj).__name__
    for f in fields(obj):
        value = getattr(obj, f.name)
        rule = field_rule(f, rules, _default(f, value))
        if rule is None:
            continue
        try:
            checked = rule(value, f.name)
        except TypeError as exc:
            raise ParamTypeError(owner, str(exc)) from None
        except ValueError as exc:
            raise ParamValueError(owner, str(exc)) from None
        if isinstance(checked, tuple) and (type(value) is not tuple or checked != value):
            object.__setattr__(obj, f.name, checked)
    for a, op, b in order:
        x, y = _field_value(obj, a), _field_value(obj, b)
        if op == "in":
            if not y[0] <= x <= y[1]:
                raise ParamValueError(owner, f"{a} must lie inside {b} = {tuple(y)!r}; got {x!r}")
        elif not _ORDER_OPS[op](x, y):
            raise ParamValueError(owner, f"{a} must be {op} {b} ({y!r}); got {x!r}")
