"""``imu-align`` drift (what residual errors cost: attitude, velocity and position error growth).

Public names
------------
COMMANDS
"""

COMMANDS: dict = {}
