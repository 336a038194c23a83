"""``imu-align batch`` and ``imu-align lot``: many units through the single commands, and their statistics.

Public names
------------
COMMANDS
"""

COMMANDS: dict = {}
