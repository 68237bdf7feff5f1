"""Compiled template filling (cosim.log.fill): every number exactly as orjson writes it, the log's own encoder."""
from __future__ import annotations

import math

import numpy as np
import orjson
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.log.fill import CENTIMETRE, INTEGER, LARGEST_DRAWN, FilledTemplate, holes


def _orjson_centimetre(x: float) -> bytes:
    # Reference: the scene's numbers before this kernel, numpy's round to the centimetre encoded by orjson.
    return orjson.dumps(float(np.round(x, 2)) + 0.0) if math.isfinite(x) else b"null"


drawn = st.floats(min_value=-LARGEST_DRAWN, max_value=LARGEST_DRAWN, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(st.lists(drawn, min_size=1, max_size=40))
def test_centimetre_numbers_are_orjsons_text_of_numpys_round(values):
    out = FilledTemplate(b"[%s]", [CENTIMETRE]).render(np.array(values)[:, None])
    assert out == [b"[" + _orjson_centimetre(x) + b"]" for x in values]


@pytest.mark.parametrize("x", [0.0, -0.0, -0.004, 0.005, 0.015, -0.015, 1.005, 2.675, 0.1, 10.0, -123.45, 99.995,
                               1e-9, 5e11, -LARGEST_DRAWN, 0.07, 0.7])
def test_halfway_and_signed_zero_cases_match_numpy_and_orjson(x):
    assert FilledTemplate(b"%s", [CENTIMETRE]).render(np.array([[x]])) == [_orjson_centimetre(x)]


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(min_value=-(2**52), max_value=2**52), min_size=1, max_size=20))
def test_integers_are_their_digits(values):
    out = FilledTemplate(b"%s", [INTEGER]).render(np.array(values, dtype=float)[:, None])
    assert out == [orjson.dumps(v) for v in values]


def test_numbers_that_are_not_finite_are_null_as_orjson_writes_them():
    out = FilledTemplate(b'{"a":%s,"b":%s}', [CENTIMETRE, INTEGER]).render(np.array([[np.nan, np.inf]]))
    assert out == [b'{"a":null,"b":null}'] == [orjson.dumps({"a": float("nan"), "b": float("inf")})]


def test_a_drawn_number_beyond_the_largest_is_clipped_to_it():
    out = FilledTemplate(b"%s", [CENTIMETRE]).render(np.array([[3e15], [-3e15]]))
    assert out == [_orjson_centimetre(LARGEST_DRAWN), _orjson_centimetre(-LARGEST_DRAWN)]


def test_rows_fill_the_holes_in_order_and_literal_percent_signs_stay():
    template = b'{"id":"50%%s of %%","t":{"sec":%s,"nsec":%s},"z":[%s,%s]}'
    assert holes(template) == 4
    values = np.array([[3, 250_000_000, 0.126, -1.0], [4, 0, 12.0, 0.004]])
    out = FilledTemplate(template, [INTEGER, INTEGER, CENTIMETRE, CENTIMETRE]).render(values)
    assert [orjson.loads(m) for m in out] == [
        {"id": "50%s of %", "t": {"sec": 3, "nsec": 250_000_000}, "z": [0.13, -1.0]},
        {"id": "50%s of %", "t": {"sec": 4, "nsec": 0}, "z": [12.0, 0.0]},
    ]
    # ... and the text is what a bytes %-template with orjson's numbers gives.
    assert out[0] == template % (b"3", b"250000000", b"0.13", b"-1.0")


def test_no_rows_give_no_messages_and_a_wrong_shape_is_refused():
    template = FilledTemplate(b"[%s,%s]", [CENTIMETRE, CENTIMETRE])
    assert template.render(np.zeros((0, 2))) == []
    with pytest.raises(ValueError, match=r"expected \(rows, 2\) numbers"):
        template.render(np.zeros((3, 1)))
    with pytest.raises(ValueError, match="2 holes, 1 kinds"):
        FilledTemplate(b"[%s,%s]", [CENTIMETRE])
