"""``python -m align.cli``: the same as the ``imu-align`` command."""

from align.cli import main

main()
