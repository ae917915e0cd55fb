"""The compiled kernels' own sin and cos (robodyn/compiled/trig.c): within 1 ulp of the true
values (long double and mpmath as references), libm's beyond their range, and every vector
lane bit for bit the scalar function."""

from __future__ import annotations

import ctypes
import platform
import subprocess
from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy as sp

from robodyn.compiled import build, codegen, simd
from robodyn.equations.c_printer import CPrinter, vector_lines

#: The bound the functions are held to, in units in the last place of the true value.
ULP_BOUND = 1.0
LIMIT = 2.0**20
SPECIAL = [0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1e-300, 7.45e-9, 7.46e-9, 1e-5]
SPECIAL += [LIMIT, np.nextafter(LIMIT, np.inf), -LIMIT, 1e6, 1e22, 1e300, np.inf, -np.inf, np.nan]


def _variant() -> tuple[str, int, str] | None:
    """The widest SIMD variant this CPU runs (None: scalar only)."""
    variants = simd.build_variants() if platform.machine().lower() in ("x86_64", "amd64") else ()
    return variants[-1] if variants else None


def _library(folder: Path, trig: str) -> ctypes.CDLL:
    """``trig`` (the generic text) instantiated on doubles and on the widest vector, behind
    two loops: ``scalar(x, s, c, n)`` and ``vector(x, s, c, n)`` (n a multiple of 8)."""
    variant = _variant()
    text = ["#include <math.h>", "#include <string.h>", codegen.trig_source(trig)]
    text.append(
        "void scalar(const double *x, double *s, double *c, long n) { for (long i = 0; i < n; ++i) rd_sincos(x[i], s + i, c + i); }"
    )
    if variant is not None:
        _, lanes, target = variant
        attribute = f'__attribute__((target("{target}")))'
        text.append(f"typedef double rds{lanes} __attribute__((vector_size({8 * lanes})));")
        text += simd.vector_trig(f"rds{lanes}", lanes, attribute)
        text.append(
            f"{attribute} void vector(const double *x, double *s, double *c, long n) {{"
            f" for (long i = 0; i < n; i += {lanes}) {{ rds{lanes} v, vs, vc; memcpy(&v, x + i, sizeof v);"
            f" rds{lanes}_sincos(v, &vs, &vc); memcpy(s + i, &vs, sizeof v); memcpy(c + i, &vc, sizeof v); }} }}"
        )
    source, library = folder / "trig.c", folder / "trig.so"
    source.write_text("\n".join(text) + "\n", encoding="utf-8")
    subprocess.run([build.find_compiler(), *build.FLAGS, str(source), "-o", str(library), "-lm"], check=True)
    return ctypes.CDLL(str(library))


@pytest.fixture(scope="module")
def trig(tmp_path_factory) -> ctypes.CDLL:
    return _library(tmp_path_factory.mktemp("trig"), codegen.TRIG.read_text(encoding="utf-8"))


def _call(library: ctypes.CDLL, function: str, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(sin x, cos x)`` by the library's ``scalar`` or ``vector`` loop."""
    count = len(x)
    x = np.ascontiguousarray(np.concatenate([x, np.zeros(-count % 8)]))
    s, c = np.empty_like(x), np.empty_like(x)
    pointer = ctypes.POINTER(ctypes.c_double)
    getattr(library, function)(*(a.ctypes.data_as(pointer) for a in (x, s, c)), ctypes.c_long(len(x)))
    return s[:count], c[:count]


def _ulps(ours: np.ndarray, true: np.ndarray) -> np.ndarray:
    """``|ours - true|`` in units in the last place of ``true`` rounded to a double."""
    rounded = true.astype(float)
    exponent = np.frexp(rounded)[1]
    ulp = np.maximum(np.ldexp(1.0, exponent - 53), 5e-324)
    return (np.abs(ours.astype(np.longdouble) - true) / ulp).astype(float)


def _arguments(count: int, seed: int) -> np.ndarray:
    """``count`` uniform in [-1e5, 1e5], the special values, and the doubles nearest and
    next to k π/2 for k up to 2^20 / (π/2)."""
    rng = np.random.default_rng(seed)
    k = np.unique(np.concatenate([np.arange(1, 64), rng.integers(64, int(LIMIT / (np.pi / 2)), size=count // 100)]))
    near = (k * (np.longdouble(np.pi) / 2 + (np.longdouble(np.pi) - np.pi) / 2)).astype(float)
    near = np.concatenate([near, np.nextafter(near, np.inf), np.nextafter(near, -np.inf)])
    return np.concatenate([rng.uniform(-1e5, 1e5, count), near, -near, SPECIAL])


def _worst(library: ctypes.CDLL, x: np.ndarray) -> tuple[float, float]:
    """The largest error of sin and cos over ``x`` (finite, within the range) in ulps,
    against long double (x87, 64-bit mantissa, exact argument reduction)."""
    s, c = _call(library, "scalar", x)
    inside = np.isfinite(x) & (np.abs(x) <= LIMIT)
    wide = x[inside].astype(np.longdouble)
    return float(_ulps(s[inside], np.sin(wide)).max()), float(_ulps(c[inside], np.cos(wide)).max())


@pytest.mark.skipif(np.finfo(np.longdouble).nmant < 63, reason="needs x87 long double as the reference")
def test_sin_and_cos_are_within_one_ulp_of_long_double(trig):
    x = _arguments(100_000, 1)
    worst = _worst(trig, x)
    assert max(worst) <= ULP_BOUND, worst


@pytest.mark.slow
@pytest.mark.skipif(np.finfo(np.longdouble).nmant < 63, reason="needs x87 long double as the reference")
def test_sin_and_cos_are_within_one_ulp_on_ten_million_arguments(trig):
    worst = max(max(_worst(trig, _arguments(1_000_000, seed))) for seed in range(10))
    assert worst <= ULP_BOUND, worst


def test_where_libm_and_ours_differ_mpmath_finds_ours_within_one_ulp(trig):
    x = _arguments(20_000, 2)
    x = x[np.isfinite(x) & (np.abs(x) <= LIMIT)]
    s, c = _call(trig, "scalar", x)
    differ = np.flatnonzero((s != np.sin(x)) | (c != np.cos(x)))[:200]
    assert len(differ) > 10  # not libm itself
    with mpmath.workprec(200):
        for i in differ:
            for ours, function in ((s[i], mpmath.sin), (c[i], mpmath.cos)):
                true = function(mpmath.mpf(float(x[i])))
                ulp = mpmath.ldexp(1, int(mpmath.floor(mpmath.log(abs(true), 2))) - 52)
                assert abs(mpmath.mpf(float(ours)) - true) <= ULP_BOUND * ulp, (x[i], ours)


def test_beyond_the_range_and_for_special_values_the_results_are_libms(trig):
    x = np.array([*SPECIAL, -1e6, 3e7, 1e308, -np.inf])
    s, c = _call(trig, "scalar", x)
    outside = ~(np.abs(x) <= LIMIT)
    with np.errstate(invalid="ignore"):
        assert np.array_equal(s[outside], np.sin(x[outside]), equal_nan=True)
        assert np.array_equal(c[outside], np.cos(x[outside]), equal_nan=True)
    assert np.array_equal(np.signbit(s[:5]), np.signbit(x[:5]))  # sin ±0 = ±0, and of subnormals
    assert np.all(c[:5] == 1.0)


@pytest.mark.skipif(_variant() is None, reason="no SIMD variant on this CPU")
def test_every_vector_lane_is_bit_for_bit_the_scalar_function(trig):
    rng = np.random.default_rng(3)
    x = np.concatenate([_arguments(20_000, 4), rng.uniform(-3e6, 3e6, 1000), [np.nan, -np.inf] * 4])
    x = x[rng.permutation(len(x))]  # out-of-range lanes mixed into vectors of in-range ones
    scalar, vector = _call(trig, "scalar", x), _call(trig, "vector", x)
    assert all(np.array_equal(a.view(np.int64), b.view(np.int64)) for a, b in zip(scalar, vector, strict=True))


@pytest.mark.skipif(np.finfo(np.longdouble).nmant < 63, reason="needs x87 long double as the reference")
def test_a_perturbed_polynomial_coefficient_exceeds_the_bound(tmp_path):
    text = codegen.TRIG.read_text(encoding="utf-8")
    coefficient = "-1.98412698298579493134e-04"
    assert coefficient in text
    perturbed = _library(tmp_path, text.replace(coefficient, "-1.98412698500000000000e-04"))
    assert max(_worst(perturbed, _arguments(10_000, 5))) > ULP_BOUND


def test_the_vector_form_pairs_own_sin_and_cos_and_refuses_libms():
    x = sp.Symbol("x")
    printer = CPrinter({x: "q[0]"}, trig="rd_")
    assert printer.expression(sp.sin(x) * sp.cos(x)) == "rd_cos(q[0])*rd_sin(q[0])"
    assert CPrinter({x: "q[0]"}).expression(sp.sin(x)) == "sin(q[0])"  # the equations' C keeps libm
    own = ["    const double t0 = rd_sin(th0);", "    const double t1 = rd_cos(th0);"]
    assert vector_lines(own, vector="v4", prefix="v4_") == ["    v4 t0, t1; v4_sincos(th0, &t0, &t1);"]
    assert vector_lines(["    const double t0 = sin(th0);"], vector="v4", prefix="v4_") is None
