"""Every job's options are checked before anything is read (align.job.check_options): a Python caller gets the
command line's one-line refusal, naming the field, instead of a TypeError deep in the estimator or a run on
a nonsense value (issue 22: ``ia.matrix(min_dwell=-1)`` ran)."""

import dataclasses
import math
import typing

import pytest

import align.api as ia
from align.errors import InputError
from align.job import check_options

SESSION = dict(log="examples/alignment/session.csv", plan="examples/alignment/plan.toml")


def _float_fields(options_type):
    hints = typing.get_type_hints(options_type, globalns=options_type.__init__.__globals__)
    return [f.name for f in dataclasses.fields(options_type) if hints[f.name] is float]


@pytest.mark.parametrize("name", ia.names())
def test_a_number_field_given_nan_or_text_is_refused_naming_the_field(name):
    job = ia.job(name)
    fields = _float_fields(job.options)
    if not fields:
        pytest.skip(f"{name} has no plain number field")
    required = {f.name: "x" for f in dataclasses.fields(job.options)
                if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING}
    for field in fields:
        try:
            options = job.options(**required, **{field: math.nan})
        except InputError:
            continue  # refused when made: as good
        except Exception:  # noqa: BLE001 - an options type that needs real inputs to be made at all
            pytest.skip(f"{name}'s options need real inputs")
        with pytest.raises(InputError) as exc:
            check_options(options)
        assert exc.value.where == "{" + field + "}"


def test_matrix_from_python_refuses_a_domain_error_and_takes_a_quantity():
    with pytest.raises(InputError, match="out of range; give a value > 0") as exc:
        ia.matrix(**SESSION, min_dwell=-1)
    assert exc.value.where == "{min_dwell}"
    with pytest.raises(InputError) as exc:
        ia.matrix(**SESSION, earth="yes")
    assert exc.value.where == "{earth}"
    assert ia.matrix(**SESSION, min_dwell="1000 ms") == ia.matrix(**SESSION, min_dwell=1.0)
