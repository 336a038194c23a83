"""``imu-align`` parts (the datasheet presets and a user's own parts file).

Public names
------------
COMMANDS
"""

COMMANDS: dict = {}
