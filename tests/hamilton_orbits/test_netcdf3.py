"""_netcdf3.RecordBuffer: a reused record's bytes are the ones record() builds."""

from __future__ import annotations

import numpy as np
import pytest

from hamilton_orbits._netcdf3 import Parts, RecordBuffer, record


def _values(rng, kinds):
    out = []
    for kind in kinds:
        shape = tuple(int(k) for k in rng.integers(1, 4, size=int(rng.integers(0, 3))))
        if kind == "f8":
            out.append(rng.normal(size=shape) * 10.0 ** rng.integers(-300, 300, size=shape))
        else:
            out.append(rng.integers(-128, 128, size=shape).astype(np.int8))
    return out


def test_a_filled_record_is_the_record_of_its_values_for_any_order_of_types():
    rng = np.random.default_rng(7)
    for _ in range(200):
        kinds = rng.choice(["f8", "i1"], size=int(rng.integers(1, 7)))
        like = _values(rng, kinds)
        buf = RecordBuffer([np.zeros_like(v) for v in like])
        for _ in range(3):  # refilled: nothing of the values before is left
            values = [rng.normal(size=v.shape) if v.dtype == np.float64 else
                      rng.integers(-128, 128, size=v.shape).astype(np.int8) for v in like]
            assert bytes(buf.fill(values)) == record(values)
            split = [Parts(np.array_split(v.reshape(-1), 2)) if v.dtype == np.float64
                     and v.size > 1 else v for v in values]
            assert bytes(buf.fill(split)) == record(values)


def test_a_value_of_another_shape_or_size_is_refused():
    buf = RecordBuffer([np.zeros(3), np.zeros(2), np.zeros(4, np.int8)])
    good = [np.zeros(3), np.zeros(2), np.zeros(4, np.int8)]
    with pytest.raises(ValueError, match=r"record variable 0: shape \(2,\)"):
        buf.fill([np.zeros(2), np.zeros(2), good[2]])
    with pytest.raises(ValueError, match=r"record variable 1: parts of 3 values"):
        buf.fill([good[0], Parts([np.zeros(1), np.zeros(2)]), good[2]])
    with pytest.raises(ValueError, match=r"record variable 2: shape \(5,\)"):
        buf.fill([good[0], good[1], np.zeros(5, np.int8)])
    with pytest.raises(ValueError, match=r"2 values for a record of 3"):
        buf.fill(good[:2])


def test_parts_of_sizes_that_make_up_for_each_other_are_refused():
    buf = RecordBuffer([np.zeros(3), np.zeros(2)])
    with pytest.raises(ValueError, match=r"record variable 1: parts of 1 values"):
        buf.fill([Parts([np.zeros(4)]), Parts([np.zeros(1)])])
