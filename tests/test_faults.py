"""Fault tests (issue 34): what granrs does with inputs and conditions that break naive code.

* a sweep's check of its axes is linear in their length (it was quadratic: one axis of
  40,000 values took 37.1 s to validate against 2.8 s for a 400 x 100 product);
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import granrs
from granrs import batch, cases
from granrs.errors import UnknownNameError

# ------------------------------------------------------------------------------------------
# The sweep's axis check


def _lines_in_batch(fn: Callable[[], Any]) -> int:
    """How many lines of ``granrs.batch`` ``fn`` executes (a count of work, not a time)."""
    count = 0
    target = batch.__file__

    def tracer(frame: Any, event: str, arg: Any) -> Any:
        nonlocal count
        if frame.f_code.co_filename != target:
            return None
        if event == "line":
            count += 1
        return tracer

    old = sys.gettrace()
    sys.settrace(tracer)
    try:
        fn()
    finally:
        sys.settrace(old)
    return count


def test_axis_check_is_linear_in_the_axis_length() -> None:
    """Issue 34: the check of a sweep's axes compared each value with every distinct value
    before it (``any(v is s for s in seen)``), so one axis of n values took n^2 / 2 steps.
    Counted in lines of granrs.batch run (not timed): doubling the axis must about double
    the work (the old check quadrupled it: 4.0x from 1,000 to 2,000 values)."""
    scene = cases.free_link(q_deg=0.0, v0=2.0)

    def check(n: int) -> int:
        values = list(np.linspace(1.0, 3.0, n))  # numpy floats: distinct objects
        axes = {"v0": batch._axis_values("v0", values)}
        return _lines_in_batch(lambda: batch._check_axes(scene, axes))

    small, large = check(1000), check(2000)
    assert small > 1000  # every value is looked at
    assert large / small < 2.2, (small, large)


def test_axis_check_still_checks_each_distinct_value() -> None:
    """The linear check still refuses a bad value of a non-numeric axis, and looks at each
    distinct object once (the same object repeated is checked once)."""
    scene = cases.free_link(q_deg=0.0, v0=2.0)
    with pytest.raises(UnknownNameError) as info:
        granrs.sweep(scene, apply_at=["tip"] * 5000 + ["nowhere"], progress=False)
    assert info.value.field == "apply_at"
