"""Input checks shared by every public function.

Each helper returns a clean ``float64`` array (or float) and raises
``ValueError`` / ``TypeError`` with a message that names the argument, what
was expected and what was given. Filters and models call these at their
boundaries so that bad input fails loudly instead of producing a silently
wrong estimate.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "as_angle",
    "as_bool",
    "as_count",
    "as_covariance",
    "as_finite_array",
    "as_finite_number",
    "as_instance",
    "as_mask",
    "as_float_array",
    "as_matrix",
    "as_positive",
    "as_probability",
    "as_quaternions",
    "as_rng",
    "as_times",
    "as_vector",
    "as_vectors3",
    "check_fields",
]


def _to_array(name: str, value) -> np.ndarray:
    if isinstance(value, (str, bytes)) or value is None:  # numpy would parse "1.0" or make NaN of None
        raise TypeError(f"{name}: expected numbers (array_like of float), got {value!r}")
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as err:
        raise TypeError(
            f"{name}: expected numbers (array_like of float), got {type(value).__name__}"
        ) from err
    return arr


def _describe_bad(arr: np.ndarray) -> str:
    n_nan = int(np.isnan(arr).sum())
    n_inf = int(np.isinf(arr).sum())
    parts = [f"{n_nan} NaN"] if n_nan else []
    parts += [f"{n_inf} inf"] if n_inf else []
    return " and ".join(parts)


def as_finite_array(name: str, value, ndim: int | None = None) -> np.ndarray:
    """Return ``value`` as a float array with only finite entries.

    Parameters
    ----------
    name : str
        Argument name used in error messages.
    value : array_like
        The input.
    ndim : int, optional
        Required number of dimensions.
    """
    arr = _to_array(name, value)
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name}: expected a {ndim}-D array, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: expected finite values, got {_describe_bad(arr)}")
    return arr


def as_float_array(name: str, value) -> np.ndarray:
    """Return ``value`` as a float array that may hold NaN (missing values) but no inf."""
    arr = _to_array(name, value)
    if np.isinf(arr).any():
        raise ValueError(f"{name}: expected finite values or NaN for missing, got {int(np.isinf(arr).sum())} inf")
    return arr


def as_vector(name: str, value, size: int | None = None) -> np.ndarray:
    """Return ``value`` as a finite 1-D float array, optionally of length ``size``.

    A scalar or an ``(n, 1)`` column is accepted and flattened, since filterpy
    stores states as columns.
    """
    arr = _to_array(name, value)
    if arr.ndim == 2 and 1 in arr.shape:
        arr = arr.reshape(-1)
    elif arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim != 1:
        raise ValueError(f"{name}: expected a vector, got shape {arr.shape}")
    if size is not None and arr.shape[0] != size:
        raise ValueError(f"{name}: expected shape ({size},), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: expected finite values, got {_describe_bad(arr)}")
    return arr


def as_matrix(name: str, value, shape: tuple[int, int]) -> np.ndarray:
    """Return ``value`` as a finite float matrix of exactly ``shape``."""
    arr = _to_array(name, value)
    if arr.shape != tuple(shape):
        raise ValueError(f"{name}: expected shape {tuple(shape)}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name}: expected finite values, got {_describe_bad(arr)}")
    return arr


def as_covariance(name: str, value, n: int, rtol: float = 1e-9, definite: bool = False) -> np.ndarray:
    """Return ``value`` as an ``(n, n)`` symmetric positive semi-definite matrix.

    A scalar is accepted for ``n == 1``. Symmetry is checked to a relative
    tolerance ``rtol`` of the largest entry; the smallest eigenvalue may be
    negative only by that same relative amount (rounding). With ``definite``
    every eigenvalue must be positive (an initial covariance: a zero variance
    would never change).
    """
    arr = _to_array(name, value)
    if arr.ndim == 0 and n == 1:
        arr = arr.reshape(1, 1)
    arr = as_matrix(name, arr, (n, n))
    scale = max(float(np.max(np.abs(arr))), np.finfo(float).tiny)
    asym = float(np.max(np.abs(arr - arr.T)))
    if asym > rtol * scale:
        raise ValueError(
            f"{name}: expected a symmetric covariance matrix, got max |A - A^T| = {asym:.3g}"
        )
    min_eig = float(np.linalg.eigvalsh(arr).min())
    if min_eig < -rtol * scale:
        raise ValueError(
            f"{name}: expected a positive semi-definite covariance matrix, "
            f"got smallest eigenvalue {min_eig:.3g}"
        )
    if definite and min_eig <= 0.0:
        raise ValueError(f"{name}: expected a positive definite covariance matrix, got smallest eigenvalue "
                         f"{min_eig:.3g}")
    return arr


def as_quaternions(name: str, q) -> np.ndarray:
    """Return ``q`` as a finite ``(..., 4)`` array of scalar-first quaternions."""
    q = as_finite_array(name, q)
    if q.ndim == 0 or q.shape[-1] != 4:
        raise ValueError(f"{name}: expected shape (..., 4) scalar-first quaternions, got {q.shape}")
    return q


def as_vectors3(name: str, v) -> np.ndarray:
    """Return ``v`` as a finite ``(..., 3)`` array of 3-vectors."""
    v = as_finite_array(name, v)
    if v.ndim == 0 or v.shape[-1] != 3:
        raise ValueError(f"{name}: expected shape (..., 3), got {v.shape}")
    return v


def _real(name: str, value) -> float:
    if isinstance(value, (bool, str, bytes)) or not np.isscalar(value) and np.ndim(value) != 0:
        raise TypeError(f"{name}: expected a real number, got {value!r}")
    try:
        return float(value)
    except (TypeError, ValueError) as err:
        raise TypeError(f"{name}: expected a real number, got {value!r}") from err


def as_finite_number(name: str, value) -> float:
    """Return ``value`` as a finite float (an angle, an offset: any sign)."""
    x = _real(name, value)
    if not np.isfinite(x):
        raise ValueError(f"{name}: expected a finite number, got {value!r}")
    return x


def as_angle(name: str, value) -> float:
    """Return ``value`` as an angle in radians within [−π, π] (a declination): a number outside is
    refused, as it is most likely in degrees."""
    x = as_finite_number(name, value)
    if abs(x) > np.pi:
        raise ValueError(f"{name}: expected radians within [-π, π], got {value!r} (degrees? use np.radians)")
    return x


def as_positive(name: str, value, allow_zero: bool = False) -> float:
    """Return ``value`` as a finite float that is > 0 (or >= 0 with ``allow_zero``)."""
    x = _real(name, value)
    ok = x >= 0 if allow_zero else x > 0
    if not np.isfinite(x) or not ok:
        bound = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{name}: expected a finite number {bound}, got {value!r}")
    return x


def as_probability(name: str, value, open_interval: bool = True) -> float:
    """Return ``value`` as a float in (0, 1) (or [0, 1] when ``open_interval`` is False)."""
    x = as_positive(name, value, allow_zero=True)
    ok = 0 < x < 1 if open_interval else 0 <= x <= 1
    if not ok:
        interval = "(0, 1)" if open_interval else "[0, 1]"
        raise ValueError(f"{name}: expected a number in {interval}, got {value!r}")
    return x


def as_count(name: str, value, low: int = 1, *, high: int | None = None) -> int:
    """Return ``value`` as an int >= ``low`` (a number of runs, a seed), and <= ``high`` if given; bools
    are refused."""
    if (isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low
            or high is not None and value > high):
        bounds = f">= {low}" if high is None else f"in [{low}, {high}]"
        raise ValueError(f"{name}: expected an int {bounds}, got {value!r}")
    return int(value)


def as_bool(name: str, value) -> bool:
    """Return ``value`` as a bool; only ``True`` / ``False`` (or a numpy bool) are accepted, not 1 or "yes"."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: expected True or False, got {value!r}")
    return bool(value)


def as_mask(name: str, value, n: int) -> np.ndarray:
    """Return ``value`` as an ``(n,)`` bool array (one flag per sample); other dtypes are refused."""
    mask = np.asarray(value)
    if mask.dtype != bool or mask.shape != (n,):
        raise ValueError(f"{name}: expected a bool array of shape ({n},), got {mask.dtype} {mask.shape}")
    return mask


def as_times(name: str, value) -> np.ndarray:
    """Return ``value`` as a non-empty, finite, strictly increasing 1-D array of times [s]."""
    t = as_finite_array(name, value, ndim=1)
    if t.size == 0:
        raise ValueError(f"{name}: expected at least one time, got an empty array")
    steps = np.diff(t)
    if np.any(steps <= 0):
        k = int(np.argmax(steps <= 0))
        raise ValueError(f"{name}: expected strictly increasing times (every dt > 0), got t[{k + 1}] = {t[k + 1]:.9g} "
                         f"after t[{k}] = {t[k]:.9g}")
    return t


def as_instance(name: str, value, cls: type):
    """Return ``value`` if it is a ``cls``, else raise ``TypeError`` naming ``name``."""
    if not isinstance(value, cls):
        raise TypeError(f"{name}: expected a {cls.__name__}, got {type(value).__name__} {value!r:.60}")
    return value


def as_rng(rng) -> np.random.Generator:
    """Return ``rng`` if it is a ``numpy.random.Generator``, else raise ``TypeError``."""
    if not isinstance(rng, np.random.Generator):
        raise TypeError(
            f"rng: expected a numpy.random.Generator (np.random.default_rng(seed)), got {type(rng).__name__}"
        )
    return rng


def _field_ok(kind: str, value) -> bool:
    if kind.startswith("optional "):
        return value is None or _field_ok(kind[len("optional "):], value)
    if kind.endswith("or 3"):  # one value or one per axis
        values = np.ravel(value) if np.ndim(value) == 1 and np.size(value) == 3 else [value]
        return all(_field_ok(kind[: -len(" or 3")], v) for v in values)
    if kind == "positives":
        return (np.ndim(value) == 1 and np.size(value) >= 1 and not isinstance(value, str)
                and all(_field_ok("positive", v) for v in np.ravel(value)))
    if kind == "vector3":
        return (np.ndim(value) == 1 and np.size(value) == 3 and not isinstance(value, str)
                and all(_field_ok("finite", v) for v in np.ravel(value)))
    if isinstance(value, (bool, str, bytes)) or np.ndim(value) != 0:
        return False
    try:
        x = float(value)
    except (TypeError, ValueError):
        return False
    return {"finite": np.isfinite(x), "positive": np.isfinite(x) and x > 0,
            "nonnegative": np.isfinite(x) and x >= 0, "probability": 0 < x < 1}[kind]


_EXPECTED = {"finite": "a finite number", "positive": "a finite number > 0", "nonnegative": "a finite number >= 0",
             "probability": "a number in (0, 1)", "vector3": "3 finite numbers",
             "positives": "a sequence of finite numbers > 0"}
_CONVERTED = {"count": as_count, "bool": as_bool}  # checked, and stored as the int or bool they return


def as_optional(convert, name: str, value, **options):
    """None for None, else ``convert(name, value, **options)`` (:func:`as_count`, :func:`as_bool` …),
    whose error then also says that None is allowed."""
    if value is None:
        return None
    try:
        return convert(name, value, **options)
    except (TypeError, ValueError) as err:
        raise type(err)(str(err).replace(", got ", " or None, got ", 1)) from None


def check_fields(obj, kinds: dict[str, str]) -> None:
    """Check a parameter dataclass's fields: ``kinds`` maps a field to ``"finite"``, ``"positive"``,
    ``"nonnegative"``, ``"probability"``, ``"count"``, ``"bool"``, ``"vector3"`` or ``"positives"``, optionally
    prefixed ``"optional "`` (None allowed) and suffixed ``" or 3"`` (one value or one per axis).
    Raises naming ``Class.field``, the expectation and the value. ``"count"`` and ``"bool"`` are
    :func:`as_count` and :func:`as_bool` (same rule, same message), and the field is set to what they return."""
    for name, kind in kinds.items():
        value = getattr(obj, name)
        optional = kind.startswith("optional ")
        convert = _CONVERTED.get(kind.removeprefix("optional "))
        if convert is not None:
            label = f"{type(obj).__name__}.{name}"
            object.__setattr__(obj, name, as_optional(convert, label, value) if optional else convert(label, value))
        elif not _field_ok(kind, value):
            base = kind.removeprefix("optional ").removesuffix(" or 3")
            expected = _EXPECTED[base] + (" (or 3 of them, one per axis)" if kind.endswith(" or 3") else "")
            expected += " or None" if kind.startswith("optional ") else ""
            error = TypeError if isinstance(value, (str, bytes)) or value is None else ValueError
            raise error(f"{type(obj).__name__}.{name}: expected {expected}, got {value!r}")
