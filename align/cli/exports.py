"""``imu-align`` export (results in the formats other programs load).

Public names
------------
COMMANDS
"""

COMMANDS: dict = {}
