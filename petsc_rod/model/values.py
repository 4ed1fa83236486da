"""The checks of a model's plain values (numbers, vectors) and the bound every number of
a problem is held to: a field that is not a number, not finite or out of range is a
RodInputError naming the field."""

import math

import numpy as np

from petsc_rod.errors import RodInputError

# Every number must be finite and at most this large in magnitude (and a positive scale,
# such as a length or a tolerance, at least its inverse): the solver forms products of
# a few of them (K / L^2, (K3 a / L)^2 / K, R h), which must stay within double
# precision.
MAX_MAGNITUDE = 1e30
# The largest strain eps = |n| / EA that an extensible line may need (docs/method.md
# §12): beyond it the linear stretch r' = (1 + eps) d3, energy EA eps^2 / 2, models no
# line material.
MAX_STRAIN = 1.0


def real(owner, value, allow_inf=False):
    """``value`` (a number, not text or bool) as a float, finite (or +inf where
    ``allow_inf``) and of magnitude at most MAX_MAGNITUDE; RodInputError naming
    ``owner`` (e.g. 'End.stiffness') otherwise."""
    if isinstance(value, (str, bytes, bool, np.bool_)) or value is None:
        raise RodInputError(f"{owner} {value!r}: expected a number")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise RodInputError(f"{owner} {value!r}: expected a number") from None
    if not (math.isfinite(number) or (allow_inf and number == math.inf)):
        raise RodInputError(f"{owner} {value!r}: expected a finite number")
    if math.isfinite(number) and abs(number) > MAX_MAGNITUDE:
        raise RodInputError(f"{owner} {value!r}: out of range: magnitudes above "
                            f"{MAX_MAGNITUDE:g} are refused")
    return number


def reals(owner, values, sizes, largest=MAX_MAGNITUDE):
    """``values`` as a float array of one of the sizes ``sizes``, every entry a finite
    number (not text or bool) of magnitude at most ``largest``; RodInputError naming
    ``owner`` otherwise."""
    expected = f"expected {' or '.join(map(str, sizes))} numbers"
    try:
        array = np.asarray(values)
    except (TypeError, ValueError):             # rows of several lengths
        array = np.asarray(None)
    if array.dtype.kind not in "iuf" or array.size not in sizes:
        raise RodInputError(f"{owner} {values!r}: {expected}")
    array = array.astype(float).ravel()
    if not np.all(np.isfinite(array)):
        raise RodInputError(f"{owner} {values!r}: {expected}, finite")
    if np.any(np.abs(array) > largest):
        raise RodInputError(f"{owner} {values!r}: out of range: magnitudes above "
                            f"{largest:g} are refused")
    return array


def optional(owner, value, check, *args):
    """``check(owner, value, *args)`` of a field that may be None."""
    return None if value is None else check(owner, value, *args)


def whole(value):
    """Whether ``value`` is a whole number (an int, not a bool)."""
    return not isinstance(value, (bool, np.bool_)) and isinstance(value, (int, np.integer))
