"""Moved: ``imu-align calibrate gyro`` lives in :mod:`align.cli.calibrate_gyro` (this name is kept for one release)."""

from align.cli.calibrate_gyro import *  # noqa: F401,F403
from align.cli.calibrate_gyro import Mounting, gyro, gyro_files, gyro_options, rotation_table  # noqa: F401
