/* The rates that bound an explicit method's step (physics/formulations/consistent.py: stiffness_rate,
 * profile_rate, torque_gain; physics/motor.py: electrical_rate), with the order of operations kept. */
#include <math.h>

#include "cam_model.h"

/* Largest rate [1/s] of the motor's own dynamics with inertia J [kg m2]: L > 0, the pole R/L plus the
 * electromechanical coupling sqrt(c_e c_m / (J L)); L = 0, the back-EMF damping c_e c_m / (R J). */
static double electrical_rate(const CamModel *m, double J)
{
    if (m->L > 0.0)
        return m->R / m->L + sqrt(m->c_e * m->c_m / (J * m->L));
    return m->c_e * m->c_m / (m->R * J);
}

double cam_stiffness_rate(const CamModel *m, const CamMode *mode, const double x[CAM_NX], int electrical)
{
    double d[4], J, omega = x[CAM_OMEGA], rate = 0.0;
    int engaged = mode->contact != 0;
    cam_kind_eval(m, x[CAM_THETA], d);   /* the follower's coordinate q and inertia I_f (s and m: the roller's) */
    J = m->J_0 + (engaged ? m->I_f * d[1] * d[1] : 0.0);
    if (engaged)
        rate = (2.0 * m->I_f * fabs(d[1] * d[2] * omega)
                + fabs(omega) * sqrt(m->I_f * J * (d[2] * d[2] + fabs(d[1] * d[3])))) / J;
    if (m->compliant) {   /* the two-mass oscillation and its damping; the motor acts on the rotor alone */
        rate += cam_shaft_rate(m, J);
        J = m->J_m;
    }
    if (m->L > 0.0) {
        if (electrical)
            rate += electrical_rate(m, J);
    } else {
        rate += electrical_rate(m, J);
    }
    return rate + m->train_rate;   /* the end mass on the train (0 without one) */
}

double cam_shaft_rate(const CamModel *m, double J)
{
    double inverse = 1.0 / m->J_m + 1.0 / J;
    return sqrt(m->k_shaft * inverse) + m->d_shaft * inverse;
}

double cam_profile_rate(const CamModel *m, const double x[CAM_NX])
{
    return fabs(x[CAM_OMEGA]) / m->feature_angle + m->train_rate;   /* a train: a radian of its phase a feature */
}

double cam_torque_gain(const CamModel *m, const CamMode *mode, const double x[CAM_NX])
{
    double d[4];
    cam_kind_eval(m, x[CAM_THETA], d);
    return m->c_m / (m->J_0 + (mode->contact != 0 ? m->I_f * d[1] * d[1] : 0.0));
}
