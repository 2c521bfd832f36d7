"""Every check in ``slamlab._validate``: values pass through, errors name the argument."""

from __future__ import annotations

import numpy as np
import pytest

from slamlab import _validate as v

# --- as_finite_array ---------------------------------------------------------------------------


def test_as_finite_array_converts_to_float():
    out = v.as_finite_array([1, 2, 3], "x")
    assert out.dtype == np.float64
    np.testing.assert_array_equal(out, [1.0, 2.0, 3.0])


def test_as_finite_array_accepts_bool_and_checks_ndim():
    out = v.as_finite_array(np.array([[True, False]]), "mask", ndim=2)
    np.testing.assert_array_equal(out, [[1.0, 0.0]])


def test_as_finite_array_keeps_float_array_without_copy():
    x = np.arange(3.0)
    assert v.as_finite_array(x, "x") is x


@pytest.mark.parametrize(
    ("value", "error", "match"),
    [
        (None, TypeError, r"^`x` must be a numeric array; got None$"),
        (["a", "b"], TypeError, r"^`x` must be a numeric array; got dtype <U1$"),
        (np.array([1, None], dtype=object), TypeError, r"^`x` must be a numeric array; got dtype object$"),
        (np.array([1 + 2j]), TypeError, r"^`x` must be real; got complex dtype complex128$"),
        ([1.0, np.nan, np.inf], ValueError, r"^`x` must be finite; got 2 NaN/inf value\(s\)$"),
    ],
)
def test_as_finite_array_errors(value, error, match):
    with pytest.raises(error, match=match):
        v.as_finite_array(value, "x")


def test_as_finite_array_ndim_error():
    with pytest.raises(ValueError, match=r"^`x` must be 2-dimensional; got shape \(3,\)$"):
        v.as_finite_array([1, 2, 3], "x", ndim=2)


# --- as_vector ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        (3.0, [3.0]),
        ([1, 2], [1.0, 2.0]),
        (np.array([[1.0], [2.0]]), [1.0, 2.0]),  # column vector
        (np.array([[1.0, 2.0]]), [1.0, 2.0]),  # row vector
    ],
)
def test_as_vector_shapes(value, expected):
    out = v.as_vector(value, "z", n=len(expected))
    assert out.shape == (len(expected),)
    np.testing.assert_array_equal(out, expected)


def test_as_vector_any_length():
    assert v.as_vector(np.zeros(5), "z").shape == (5,)


def test_as_vector_not_a_vector():
    with pytest.raises(ValueError, match=r"^`z` must be a vector of shape \(2,\); got shape \(2, 2\)$"):
        v.as_vector(np.eye(2), "z", 2)
    with pytest.raises(ValueError, match=r"^`z` must be a vector of shape \(any,\); got shape \(2, 2, 1\)$"):
        v.as_vector(np.zeros((2, 2, 1)), "z")


def test_as_vector_wrong_length():
    with pytest.raises(ValueError, match=r"^`z` must have length 3; got shape \(2,\)$"):
        v.as_vector([1.0, 2.0], "z", 3)


def test_as_vector_passes_on_array_errors():
    with pytest.raises(ValueError, match=r"^`z` must be finite"):
        v.as_vector([np.nan], "z")


# --- as_measurement --------------------------------------------------------------------------


def test_as_measurement_fast_path_returns_same_array():
    z = np.array([1.0, 2.0])
    assert v.as_measurement(z, "z", 2) is z


def test_as_measurement_large_finite_values_pass():
    z = np.array([1e200, 1.0])  # z @ z overflows to inf, yet every value is finite
    assert v.as_measurement(z, "z", 2) is z


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_as_measurement_fast_path_non_finite(bad):
    with pytest.raises(ValueError, match=r"^`z` must be finite; got 1 NaN/inf value\(s\)$"):
        v.as_measurement(np.array([1.0, bad]), "z", 2)


def test_as_measurement_falls_back_to_as_vector():
    np.testing.assert_array_equal(v.as_measurement([1, 2], "z", 2), [1.0, 2.0])
    np.testing.assert_array_equal(v.as_measurement(np.array([[1.0], [2.0]]), "z", 2), [1.0, 2.0])
    with pytest.raises(ValueError, match=r"^`z` must have length 3; got shape \(2,\)$"):
        v.as_measurement(np.array([1.0, 2.0]), "z", 3)
    with pytest.raises(TypeError, match=r"^`z` must be a numeric array; got None$"):
        v.as_measurement(None, "z", 2)


# --- as_matrix ---------------------------------------------------------------------------------


def test_as_matrix_passes_and_accepts_scalar_for_1x1():
    np.testing.assert_array_equal(v.as_matrix([[1, 2], [3, 4]], "F", (2, 2)), [[1.0, 2.0], [3.0, 4.0]])
    assert v.as_matrix(5.0, "R", (1, 1)).shape == (1, 1)
    assert v.as_matrix(np.zeros((3, 7)), "H", (3, None)).shape == (3, 7)
    assert v.as_matrix(np.zeros((4, 2)), "H").shape == (4, 2)


def test_as_matrix_not_2d():
    with pytest.raises(ValueError, match=r"^`F` must be a 2-D matrix of shape \(2, 2\); got shape \(2,\)$"):
        v.as_matrix([1.0, 2.0], "F", (2, 2))
    with pytest.raises(ValueError, match=r"^`F` must be a 2-D matrix of shape \(rows, cols\); got shape \(\)$"):
        v.as_matrix(1.0, "F")


def test_as_matrix_wrong_shape():
    with pytest.raises(ValueError, match=r"^`H` must have shape \(2, any\); got shape \(3, 2\)$"):
        v.as_matrix(np.zeros((3, 2)), "H", (2, None))


# --- as_covariance -----------------------------------------------------------------------------


def test_as_covariance_passes_and_symmetrises():
    P = np.array([[2.0, 1.0 + 1e-12], [1.0, 2.0]])
    out = v.as_covariance(P, "P", 2)
    np.testing.assert_array_equal(out, out.T)
    np.testing.assert_allclose(out, P, atol=1e-11)


def test_as_covariance_scalar_and_semidefinite():
    np.testing.assert_array_equal(v.as_covariance(4.0, "R", 1), [[4.0]])
    np.testing.assert_array_equal(v.as_covariance(np.zeros((2, 2)), "Q"), np.zeros((2, 2)))
    v.as_covariance([[1.0, 1.0], [1.0, 1.0]], "P")  # singular but PSD


def test_as_covariance_not_square():
    with pytest.raises(ValueError, match=r"^`P` must be a square matrix; got shape \(2, 3\)$"):
        v.as_covariance(np.zeros((2, 3)), "P")


def test_as_covariance_wrong_size():
    with pytest.raises(ValueError, match=r"^`P` must have shape \(3, 3\); got shape \(2, 2\)$"):
        v.as_covariance(np.eye(2), "P", 3)


def test_as_covariance_not_symmetric():
    with pytest.raises(ValueError, match=r"^`P` must be symmetric; largest \|P - P\^T\| entry is 1.00e\+00$"):
        v.as_covariance([[1.0, 1.0], [0.0, 1.0]], "P")


def test_as_covariance_negative_eigenvalue():
    with pytest.raises(
        ValueError, match=r"^`P` must be symmetric positive semi-definite; smallest eigenvalue -1.00e\+00$"
    ):
        v.as_covariance([[1.0, 0.0], [0.0, -1.0]], "P")


def test_as_covariance_tolerates_rounding_negative_eigenvalue():
    P = np.array([[1.0, 1.0], [1.0, 1.0]]) - 1e-13 * np.eye(2)
    v.as_covariance(P, "P")


# --- as_image ----------------------------------------------------------------------------------


def test_as_image_returns_array_as_given():
    img = np.zeros((4, 5), dtype=np.uint8)
    assert v.as_image(img) is img
    color = np.zeros((4, 5, 3))
    assert v.as_image(color, "left", allow_color=True) is color
    assert v.as_image(np.zeros((2, 2, 4)), allow_color=True).shape == (2, 2, 4)


@pytest.mark.parametrize(
    ("value", "kwargs", "error", "match"),
    [
        (np.array([["a"]]), {}, TypeError, r"^`img` must be a numeric image array; got dtype <U1$"),
        (np.zeros(3), {}, ValueError, r"^`img` must have shape \(H, W\); got shape \(3,\)$"),
        (np.zeros((2, 2, 3)), {}, ValueError, r"^`img` must have shape \(H, W\); got shape \(2, 2, 3\)$"),
        (
            np.zeros((2, 2, 2)),
            {"allow_color": True},
            ValueError,
            r"^`img` must have shape \(H, W\) or \(H, W, 3\); got shape \(2, 2, 2\)$",
        ),
        (np.zeros((0, 3)), {}, ValueError, r"^`img` must not be empty; got shape \(0, 3\)$"),
        (np.array([[0.0, np.nan]]), {}, ValueError, r"^`img` must be finite; got NaN/inf pixels$"),
    ],
)
def test_as_image_errors(value, kwargs, error, match):
    with pytest.raises(error, match=match):
        v.as_image(value, "img", **kwargs)


def test_as_image_default_name():
    with pytest.raises(ValueError, match=r"^`image` must have shape"):
        v.as_image(np.zeros(3))


# --- as_rng ------------------------------------------------------------------------------------


def test_as_rng_normalises():
    gen = np.random.default_rng(1)
    assert v.as_rng(gen) is gen
    assert isinstance(v.as_rng(None), np.random.Generator)
    assert v.as_rng(7).integers(1000) == np.random.default_rng(7).integers(1000)
    assert v.as_rng(np.int64(7)).integers(1000) == np.random.default_rng(7).integers(1000)
    seq = np.random.SeedSequence(3)
    assert v.as_rng(seq).integers(1000) == np.random.default_rng(np.random.SeedSequence(3)).integers(1000)


def test_as_rng_negative_seed():
    with pytest.raises(ValueError, match=r"^`rng` seed must be non-negative; got -1$"):
        v.as_rng(-1)


@pytest.mark.parametrize(("value", "typename"), [(True, "bool"), (1.5, "float"), ("7", "str")])
def test_as_rng_wrong_type(value, typename):
    with pytest.raises(TypeError, match=rf"^`rng` must be a numpy Generator, an int seed, a SeedSequence or None; got {typename}$"):
        v.as_rng(value, "rng")


# --- check_int ---------------------------------------------------------------------------------


def test_check_int_passes():
    assert v.check_int(3, "n", minimum=1, maximum=3) == 3
    out = v.check_int(np.int32(4), "n")
    assert out == 4
    assert type(out) is int


@pytest.mark.parametrize(("value", "typename"), [(True, "bool"), (2.0, "float"), ("2", "str")])
def test_check_int_wrong_type(value, typename):
    with pytest.raises(TypeError, match=rf"^`n` must be an integer; got {typename}$"):
        v.check_int(value, "n")


def test_check_int_bounds():
    with pytest.raises(ValueError, match=r"^`n` must be >= 1; got 0$"):
        v.check_int(0, "n", minimum=1)
    with pytest.raises(ValueError, match=r"^`n` must be <= 5; got 6$"):
        v.check_int(6, "n", maximum=5)


# --- check_positive ----------------------------------------------------------------------------


def test_check_positive_passes():
    assert v.check_positive(2, "sigma") == 2.0
    assert v.check_positive(np.float64(0.5), "sigma") == 0.5
    assert v.check_positive(0, "sigma", allow_zero=True) == 0.0


@pytest.mark.parametrize(("value", "typename"), [(True, "bool"), ("1", "str"), (None, "NoneType")])
def test_check_positive_wrong_type(value, typename):
    with pytest.raises(TypeError, match=rf"^`sigma` must be a real number; got {typename}$"):
        v.check_positive(value, "sigma")


@pytest.mark.parametrize(
    ("value", "kwargs", "match"),
    [
        (float("inf"), {}, r"^`sigma` must be finite; got inf$"),
        (float("nan"), {}, r"^`sigma` must be finite; got nan$"),
        (0, {}, r"^`sigma` must be > 0; got 0.0$"),
        (-1, {}, r"^`sigma` must be > 0; got -1.0$"),
        (-1, {"allow_zero": True}, r"^`sigma` must be >= 0; got -1.0$"),
    ],
)
def test_check_positive_values(value, kwargs, match):
    with pytest.raises(ValueError, match=match):
        v.check_positive(value, "sigma", **kwargs)


# --- check_probability -------------------------------------------------------------------------


def test_check_probability_passes():
    assert v.check_probability(0.25, "p") == 0.25


@pytest.mark.parametrize(
    ("value", "match"),
    [(0, r"^`p` must be > 0; got 0.0$"), (1, r"^`p` must be in \(0, 1\); got 1.0$"), (1.5, r"got 1.5$")],
)
def test_check_probability_range(value, match):
    with pytest.raises(ValueError, match=match):
        v.check_probability(value, "p")


def test_check_probability_type():
    with pytest.raises(TypeError, match=r"^`p` must be a real number; got str$"):
        v.check_probability("0.5", "p")


# --- check_choice / check_callable -------------------------------------------------------------


def test_check_choice():
    assert v.check_choice("ukf", "method", ("kf", "ekf", "ukf")) == "ukf"
    assert v.check_choice("a", "mode", iter(["a", "b"])) == "a"
    with pytest.raises(ValueError, match=r"^`mode` must be one of 'a', 'b'; got 'c'$"):
        v.check_choice("c", "mode", ["a", "b"])
    with pytest.raises(ValueError, match=r"^`mode` must be one of 'a', 'b'; got 1$"):
        v.check_choice(1, "mode", ["a", "b"])


def test_check_callable():
    assert v.check_callable(len, "f") is len
    with pytest.raises(TypeError, match=r"^`f` must be callable; got int$"):
        v.check_callable(3, "f")


def test_every_public_check_is_tested():
    tested = {
        "as_covariance", "as_finite_array", "as_image", "as_matrix", "as_measurement", "as_path", "parse_numbers", "as_rng", "as_vector",
        "check_callable", "check_choice", "check_int", "check_positive", "check_probability",
    }
    assert set(v.__all__) == tested


# --- as_path -------------------------------------------------------------------------------------


def test_as_path_accepts_str_and_pathlike(tmp_path):
    f = tmp_path / "log.txt"
    f.write_text("x")
    assert v.as_path(str(f), kind="file") == f
    assert v.as_path(tmp_path, kind="dir") == tmp_path


def test_as_path_errors_name_the_argument(tmp_path):
    with pytest.raises(TypeError, match=r"`log` must be a str or os\.PathLike path; got int"):
        v.as_path(3, "log")
    with pytest.raises(FileNotFoundError, match="`log`: no file at"):
        v.as_path(tmp_path / "missing.log", "log", kind="file")
    with pytest.raises(FileNotFoundError, match="`folder`: no folder at"):
        v.as_path(tmp_path / "a.txt", "folder", kind="dir")


def test_parse_numbers_names_the_place_and_the_field():
    np.testing.assert_array_equal(v.parse_numbers(["1", "-2e3", "inf"], "f"), [1.0, -2000.0, np.inf])
    with pytest.raises(ValueError, match=r"exp2\.dat line 7: field 2 is not a number: '1,5'"):
        v.parse_numbers(["1", "2", "1,5"], "exp2.dat line 7")
