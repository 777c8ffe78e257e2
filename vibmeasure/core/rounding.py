"""How numbers are written for people: one rule for a value with its standard deviation, used by the
report, the command line and the results' ``repr``.

The std is given to two significant digits and the value to the same decimal place (the GUM's
practice, JCGM 100:2008 7.2.6): "0.012346 ± 0.000012", never "0.0123456 ± 1.2e-05" (digits the std
says are noise) or "24 ± 0.00029" (a value cut coarser than its own std). A value without a usable
std keeps ``digits`` significant digits. Very large or small values share one power of ten.
"""

from __future__ import annotations

import math

__all__ = ["with_std", "plain", "band", "MAX_DIGITS"]

#: significant digits a value is never printed beyond: a std below the 11th digit is round-off, not data
MAX_DIGITS = 11


def _finite(v) -> bool:
    try:
        return v is not None and math.isfinite(float(v))
    except (TypeError, ValueError):
        return False


def _no_negative_zero(s: str) -> str:
    """'-0', '-0.000' and '-0.0e-05' read as a sign the value does not have."""
    if s.startswith("-") and not any(c in "123456789" for c in s.split("e")[0]):
        return s[1:]
    return s


def plain(value, digits: int = 6) -> str:
    """A value to ``digits`` significant digits ("n/a" when missing or not finite, never "-0").

    Parameters
    ----------
    value : float or None
        The number.
    digits : int
        Significant digits.

    Returns
    -------
    str

    Examples
    --------
    >>> from vibmeasure.core.rounding import plain
    >>> plain(23.70123456), plain(-1e-20, 3), plain(float("nan"))
    ('23.7012', '-1e-20', 'n/a')
    """
    if not _finite(value):
        return "n/a"
    return _no_negative_zero(f"{float(value):.{int(digits)}g}")


def with_std(value, std, *, sig: int = 2, digits: int = 6) -> tuple[str, str]:
    """A value and its standard deviation as two strings rounded by one rule: the std to ``sig``
    significant digits, the value to the std's last decimal place.

    Parameters
    ----------
    value : float
        The estimate.
    std : float or None
        Its standard deviation; missing, zero or not finite: the value keeps ``digits`` significant
        digits and the std reads "n/a".
    sig : int
        Significant digits of the std.
    digits : int
        Significant digits of a value without a usable std.

    Returns
    -------
    (str, str)
        The value and the std.

    Examples
    --------
    >>> from vibmeasure.core.rounding import with_std
    >>> with_std(0.0123456, 1.234e-5)
    ('0.012346', '0.000012')
    >>> with_std(24.000123, 0.00029)
    ('24.00012', '0.00029')
    >>> with_std(123456.0, 5600.0)
    ('123500', '5600')
    >>> with_std(2.5e-7, 3.1e-9)
    ('2.500e-07', '0.031e-07')
    >>> with_std(20.003999600079972, 8.0e-14)         # noise-free data: MAX_DIGITS at most
    ('20.003999600', '8.0e-14')
    """
    if not _finite(value):
        return "n/a", plain(std, sig) if _finite(std) else "n/a"
    if not _finite(std) or float(std) <= 0:
        return plain(value, digits), "n/a"
    value, std = float(value), float(std)
    last = math.floor(math.log10(std)) - (int(sig) - 1)       # power of ten of the std's last digit
    if value != 0 and math.floor(math.log10(abs(value))) - last + 1 > MAX_DIGITS:
        # a std at the round-off level (noise-free data): more digits would be the arithmetic's, not the data's
        return _no_negative_zero(f"{value:#.{MAX_DIGITS}g}".rstrip(".")), f"{std:.{int(sig) - 1}e}"
    big = max(abs(value), std)
    if big >= 1e7 or big < 1e-4:                               # one shared power of ten
        p = math.floor(math.log10(big))
        dec = max(p - last, 0)
        return (_no_negative_zero(f"{value / 10 ** p:.{dec}f}e{p:+03d}"), f"{std / 10 ** p:.{dec}f}e{p:+03d}")
    if last < 0:
        return _no_negative_zero(f"{value:.{-last}f}"), f"{std:.{-last}f}"
    step = 10 ** last                    # half away from zero, as a person rounds (not to even)
    return (_no_negative_zero(f"{math.copysign(math.floor(abs(value) / step + 0.5), value) * step:.0f}"),
            f"{math.floor(std / step + 0.5) * step:.0f}")


def band(lo, hi, digits: int = 4) -> str:
    """A frequency band as "lo-hi" to ``digits`` significant digits ("1.011-819.2", not
    "1.01111-819.2").

    Parameters
    ----------
    lo, hi : float
        The band's edges.
    digits : int
        Significant digits of each edge.

    Returns
    -------
    str

    Examples
    --------
    >>> from vibmeasure.core.rounding import band
    >>> band(1.01111, 819.2)
    '1.011-819.2'
    """
    return f"{plain(lo, digits)}-{plain(hi, digits)}"
