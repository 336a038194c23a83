"""Mechanical tolerance analysis: how far the gyro axes sit from the system axes once the
IMU is screwed onto its ledges (reference section 2, Eq 1-4)."""
