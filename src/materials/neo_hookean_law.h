/* The neo-Hookean stress of seed 003 eq. 6-7 (materials/neo_hookean.c) as
 * one function of its moduli, compiled for the CPU and the device step
 * (src/gpu) alike: P = mu J^-2/3 (F - (F:F) / (3 J) H) + kappa (J - 1) H. */
#ifndef SPH_NEO_HOOKEAN_LAW_H
#define SPH_NEO_HOOKEAN_LAW_H

#include <math.h>

#include "core/hd.h"
#include "core/tensor.h"

SPH_HD static inline void sph_neo_hookean_law(double mu, double kappa,
                                              const double F[9],
                                              const double H[9], double J,
                                              double P[9]) {
  double j23 = pow(J, -2.0 / 3.0);
  double ff = sph_mat3_ddot(F, F);
  double p = kappa * (J - 1.0);
  for (int k = 0; k < 9; ++k)
    P[k] = mu * j23 * (F[k] - ff / (3.0 * J) * H[k]) + p * H[k];
}

#endif
