"""Every job's keyword-only call shows its options (a new user's `help(ia.matrix)` listed none of them)."""

import dataclasses
import inspect

import pytest

import align.api as ia

CALLS = {"matrix": "MatrixOptions", "apply": "ApplyOptions", "allan": "AllanOptions", "plan": "PlanOptions",
         "ferraris": "FerrarisOptions", "calibrate_accel": "AccelOptions", "calibrate_mag": "MagOptions",
         "calibrate_gyro": "GyroOptions", "budget": "BudgetOptions", "allowable": "AllowableOptions",
         "check": "CheckOptions", "drift": "DriftOptions", "calibrate_thermal": "ThermalOptions",
         "calibrate_positions": "PositionsOptions", "warmup": "WarmupOptions", "repeatability": "RepeatabilityOptions",
         "verify": "VerifyOptions", "calibrate_thermal_matrix": "MatrixThermalOptions"}


@pytest.mark.parametrize("call", CALLS)
def test_a_job_call_lists_every_field_of_its_options_keyword_only(call):
    fn, options = getattr(ia, call), getattr(ia, CALLS[call])
    params = inspect.signature(fn).parameters
    for f in dataclasses.fields(options):
        if f.init:
            assert f.name in params, f"{call} does not show {f.name}"
    assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in params.values())
    with pytest.raises(TypeError):
        fn("a positional argument")


def test_every_registered_job_has_its_call_and_options_in_the_api():
    names = {ia.job(name).name for name in ia.names()}
    assert names == set(ia.JOBS)
    for name in ia.names():
        assert ia.job(name).options.__name__ in CALLS.values()
