"""calibrate ferraris | accel | mag | gyro: the command's --json is the library job's result (provenance aside),
its options built by the command's builder; the one column convention (duplicates and missing names one line,
exit 2; --time-column; the old default names accepted)."""

import numpy as np
import pytest
from support import SHARED

import align.api as ia
from align.cli.builders import files_builder, options_builder
from align.io.source import LogSource
from align.results import load_result
from align.values import approx_equal

FERRARIS = SHARED / "data" / "multiposition" / "imucal_ferraris"
HMC = SHARED / "data" / "magnetometer" / "hmc5883l_sunsided" / "hmc5883l_compass.csv"
XSENS = SHARED / "data" / "multiposition" / "xsens_mti_imu_tk"
PNG = b"\x89PNG\r\n\x1a\n"


def same(cli_json, lib):
    got = load_result(cli_json)
    assert got.provenance is not None and got.provenance.job == lib.provenance.job
    assert [(f.role, f.sha256) for f in got.provenance.files] == [(f.role, f.sha256) for f in lib.provenance.files]
    assert approx_equal(got.replace(provenance=None), lib.replace(provenance=None), rtol=1e-9)


@pytest.fixture(scope="module")
def poses(tmp_path_factory):
    """A simulated multi-position session (posesim), gyro columns under their old default names gyr_x..."""
    from align.calibration.posesim import PoseSessionSpec, random_sensors, simulate_poses

    rng = np.random.default_rng(31)
    s = simulate_poses(PoseSessionSpec(fs=50.0, poses=14, init_s=20.0), *random_sensors(rng), rng)
    log = tmp_path_factory.mktemp("poses") / "session.csv"
    np.savetxt(log, np.column_stack([s.t, s.acc, np.rad2deg(s.gyr)]), delimiter=",",
               header="time,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z", comments="")
    return log


def test_ferraris_cli_is_the_library_job(run_cli, tmp_path):
    log, sec, out, imu = (FERRARIS / "example_ferraris_session.csv", FERRARIS / "example_ferraris_session_list.json",
                          tmp_path / "cal.json", tmp_path / "imucal.json")
    res = run_cli("calibrate", "ferraris", log, "--sections", sec, "--rate-hz", "102.4", "--json", out,
                  "--imucal-json", imu)
    assert res.code == 0, res.err
    lib = ia.ferraris(log=log, rate_hz=102.4, sections=sec)  # gyr_x, acc_x: found without --columns
    same(out, lib)
    assert imu.exists()
    built = options_builder("calibrate ferraris")(log=log, sections=sec, rate_hz=102.4, turn_angle=np.deg2rad(-360),
                                                   gravity=9.80665, json_out=tmp_path / "ignored.json")
    assert approx_equal(ia.job("calibrate ferraris").run(built).replace(provenance=None), lib.replace(provenance=None))
    files = files_builder("calibrate ferraris")(lib, None, {"imucal_json": imu})
    assert files[0][0] == imu and files[0][1] == imu.read_text()


def test_accel_cli_is_the_library_job(run_cli, tmp_path):
    log, out, png = XSENS / "xsens_acc.mat", tmp_path / "acc.json", tmp_path / "acc.png"
    res = run_cli("calibrate", "accel", log, "--columns", "col0,col1,col2,col3", "--accel-units", "counts",
                  "--gravity", "9.81744 m/s^2", "--init-static", "50 s", "--json", out, "--plot", png)
    assert res.code == 0, res.err
    lib = ia.calibrate_accel(log=log, columns="col0,col1,col2,col3", units="counts", gravity=9.81744,
                             init_static_s=50.0)
    same(out, lib)
    assert png.read_bytes().startswith(PNG)
    # data columns and --time-column: the same session
    out2 = tmp_path / "acc2.json"
    res = run_cli("calibrate", "accel", log, "--columns", "col1,col2,col3", "--time-column", "col0", "--accel-units",
                  "counts", "--gravity", "9.81744 m/s^2", "--init-static", "50 s", "--json", out2)
    assert res.code == 0, res.err
    assert approx_equal(load_result(out2).sensor("accelerometer"), lib.sensor("accelerometer"))


def test_mag_cli_is_the_library_job(run_cli, tmp_path):
    out, png = tmp_path / "mag.json", tmp_path / "mag.png"
    res = run_cli("calibrate", "mag", HMC, "--columns", "mag_x_gauss,mag_y_gauss,mag_z_gauss", "--mag-units", "gauss",
                  "--field", "0.5 gauss", "--json", out, "--plot", png)
    assert res.code == 0, res.err
    lib = ia.calibrate_mag(log=HMC, columns="mag_x_gauss,mag_y_gauss,mag_z_gauss", units="gauss", field=0.5e-4)
    same(out, lib)
    assert png.read_bytes().startswith(PNG)


def test_gyro_cli_is_the_library_job(run_cli, poses, tmp_path):
    out, png = tmp_path / "gyro.json", tmp_path / "gyro.png"
    res = run_cli("calibrate", "gyro", poses, "--json", out, "--plot", png, "--mounting", "+y,-x,+z")
    assert res.code == 0, res.err
    lib = ia.calibrate_gyro(log=poses, mounting=((0, 1, 0), (-1, 0, 0), (0, 0, 1)), mounting_text="+y,-x,+z")
    same(out, lib)
    assert png.read_bytes().startswith(PNG) and "largest residual" in res.out
    # the accelerometer's columns named, and the gyro's with the time column first (the old spelling)
    out2 = tmp_path / "gyro2.json"
    res = run_cli("calibrate", "gyro", poses, "--gyro-columns", "time,gyr_x,gyr_y,gyr_z", "--accel-columns",
                  "acc_x,acc_y,acc_z", "--json", out2)
    assert res.code == 0, res.err
    plain = ia.calibrate_gyro(log=LogSource(path=poses, columns=("gyr_x", "gyr_y", "gyr_z")))
    same(out2, plain)


def one_line(res, code=2):
    assert res.code == code, (res.code, res.err)
    assert res.err.strip().count("\n") == 0 and "Traceback" not in res.err and "internal error" not in res.err
    return res.err


@pytest.mark.parametrize("args, flag", [
    (("calibrate", "mag", HMC, "--columns", "mag_x_gauss,mag_y_gauss,mag_x_gauss"), "--columns"),
    (("calibrate", "mag", HMC, "--columns", "mag_x_gauss,mag_y_gauss,nope"), "--columns"),
    (("calibrate", "mag", HMC, "--columns", "mag_x_gauss,mag_y_gauss,mag_z_gauss", "--accel-columns",
      "mag_x_gauss,a,b"), "--accel-columns"),
    (("calibrate", "ferraris", FERRARIS / "example_ferraris_session.csv", "--sections",
      FERRARIS / "example_ferraris_session_list.json", "--rate-hz", "102.4", "--gyro-columns", "gyr_x,gyr_x,gyr_z"),
     "--gyro-columns"),
    (("calibrate", "ferraris", FERRARIS / "example_ferraris_session.csv", "--sections",
      FERRARIS / "example_ferraris_session_list.json", "--rate-hz", "102.4", "--accel-columns", "acc_x,acc_y,nope"),
     "--accel-columns"),
    (("calibrate", "accel", XSENS / "xsens_acc.mat", "--columns", "col1,col1,col3", "--time-column", "col0"),
     "--columns"),
    (("calibrate", "accel", XSENS / "xsens_acc.mat", "--columns", "col0,col1,col2", "--time-column", "col0"),
     "--time-column"),
])
def test_duplicate_and_missing_names_are_one_line(run_cli, args, flag):
    assert flag in one_line(run_cli(*args))


def test_calibrate_gyro_column_refusals(run_cli, poses):
    assert "--gyro-columns" in one_line(run_cli("calibrate", "gyro", poses, "--gyro-columns", "gyr_x,gyr_x,gyr_z"))
    assert "--accel-columns" in one_line(run_cli("calibrate", "gyro", poses, "--accel-columns", "acc_x,nope,acc_z"))
    err = one_line(run_cli("calibrate", "gyro", poses, "--time-column", "stamp"))
    assert "stamp" in err
