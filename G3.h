/* imu-align alignment from SN0001.csv; written by imu-align 0.2.0 */
/* convention: correcting, w = A (g - b) with A = M^-1 of the model g = M w + b (g raw reading, b bias, w true rate); rows of M are gyro axes */
/* frame: w in the system frame of the test (the rate table's axes) */
/* units: A dimensionless; b in deg/s, the unit of the readings g */
/* literals: the nearest float (IEEE single) to each value, 9 significant digits */
#ifndef IMU_ALIGN_H
#define IMU_ALIGN_H

/* alignment matrix A = M^-1, dimensionless: w = A (g - b) */
static const float IMU_ALIGN_A[3][3] = {
    {1.00191283f, -0.000116000047f, -0.00034492003f},
    {5.89617775e-05f, 0.999432862f, 4.56724265e-05f},
    {0.000172556087f, 7.7732504e-05f, 1.00065517f}
};

/* gyro bias b in deg/s */
static const float IMU_ALIGN_BIAS[3] = {0.07239151f, 0.241178885f, 0.132700741f};

#endif /* IMU_ALIGN_H */
