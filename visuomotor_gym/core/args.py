"""Constructor-argument checks shared by every env: each error names the argument, the value it got
and what is allowed (Gymnasium users meet these first, before any physics runs)."""

from __future__ import annotations

import math
from dataclasses import fields
from numbers import Integral, Real
from typing import Any


def choice(value: Any, allowed, arg_name: str):
    """``value`` if it is one of ``allowed``, else ``ValueError`` listing the allowed values."""
    if isinstance(value, str) or value is None:
        if value in allowed:
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
    """Accept a params dataclass, a dict of its fields, or None (defaults)."""
    if value is None:
        return cls()
    if isinstance(value, cls):
        return value
    if isinstance(value, dict):
        allowed = {f.name for f in fields(cls)}
        unknown = sorted(set(value) - allowed)
        if unknown:
            raise TypeError(f"{arg_name}: unknown field(s) {unknown}; allowed: {sorted(allowed)}")
        return cls(**value)
    raise TypeError(f"{arg_name} must be a {cls.__name__}, a dict of its fields or None; got {type(value).__name__}")


def whole_multiple(value: float, unit: float, arg_name: str, *, minimum: int = 0) -> int:
    """``value / unit`` when it is a whole number >= ``minimum`` (to 1e-9), else ``ValueError``."""
    ratio = value / unit
    if not (abs(ratio - round(ratio)) < 1e-9 and round(ratio) >= minimum):
        least = "a positive" if minimum >= 1 else "a non-negative"
        raise ValueError(f"{arg_name}={value!r} must be {least} whole multiple of {unit!r} s")
    return int(round(ratio))
