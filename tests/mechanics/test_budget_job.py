"""The budget job called from Python: the reference's Example 1 numbers, its options, its provenance."""

import pytest
from mounts import EXAMPLE1

from align.errors import InputError
from align.units import DEG
from align.values import approx_equal
from mechanics.jobs import BUDGET, BudgetOptions, budget


def test_example_1_from_a_python_call():
    b = budget(mount=str(EXAMPLE1))  # a str path is accepted
    # reference alignment-basics.md, Example 1: Eq 2-4 and Eq 1 with theta_SYS = max(theta_X, theta_Y, theta_Z)
    assert b.tilt_x / DEG == pytest.approx(0.30155, abs=5e-6)
    assert b.tilt_y / DEG == pytest.approx(0.27949, abs=5e-6)
    assert b.skew_z / DEG == pytest.approx(0.83736, abs=5e-6)
    assert b.total / DEG == pytest.approx(1.3043, abs=5e-5)
    assert b.monte_carlo is None and b.inputs == {}


def test_the_job_stamps_its_provenance_and_its_monte_carlo_follows_the_seed():
    opts = BudgetOptions(mount=EXAMPLE1, monte_carlo=5000, seed=3)
    done = []
    b = BUDGET.run(opts, progress=done.append)
    assert sum(done) == 5000 and b.monte_carlo.n == 5000
    assert b.provenance.job == "budget"
    (mount,) = b.provenance.files
    assert mount.role == "mount" and mount.size == EXAMPLE1.stat().st_size and len(mount.sha256) == 64
    assert b.provenance.options["monte_carlo"] == 5000 and b.provenance.options["seed"] == 3
    assert "parts_table" not in b.provenance.options
    again = budget(mount=EXAMPLE1, monte_carlo=5000, seed=3)
    assert approx_equal(again, b, rtol=0)
    other = budget(mount=EXAMPLE1, monte_carlo=5000, seed=4)
    assert not approx_equal(other.monte_carlo, b.monte_carlo, rtol=0)


def test_a_parts_file_is_recorded_and_a_bad_count_is_refused(tmp_path):
    parts, mount = tmp_path / "parts.toml", tmp_path / "mount.toml"
    parts.write_text('[MY-IMU]\nkind = "module"\naxis_to_package = { value = "0.6 deg", source = "rev B", '
                     'confirmed = true }\n')
    mount.write_text(EXAMPLE1.read_text().replace('part = "ADIS16485"', 'part = "MY-IMU"')
                     .replace('axis_to_package = "1 deg"\n', ""))
    b = budget(mount=mount, parts=parts)
    assert b.inputs == {"parts": str(parts)} and b.imu / DEG == pytest.approx(0.6)
    assert [f.role for f in b.provenance.files] == ["mount", "parts"]
    with pytest.raises(InputError) as bad:
        BudgetOptions(mount=EXAMPLE1, monte_carlo=-1)
    assert bad.value.fields == ["monte_carlo"]


def test_the_api_names_the_same_job():
    import align.api as ia

    assert ia.job("budget") is BUDGET and ia.BudgetOptions is BudgetOptions
    assert approx_equal(ia.budget(mount=EXAMPLE1), budget(mount=EXAMPLE1))
