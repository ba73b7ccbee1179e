/* The options of ul-sph's method block (seed 002): the shear force (OG,
 * OAS with its artificial stress, ENOG with zeta), single- or
 * dual-criteria time stepping (eq. 25-29), the continuity equation's
 * pressure term, the dissipation limiter of eq. 16 and the two CFL
 * numbers. */
#include "methods/ul_sph/ul_sph_impl.h"

/* zeta of shear: laplacian and the artificial_stress block of shear:
 * artificial-stress (each refused with the other shear) */
static sph_status shear_options_parse(sph_node *opt, int dim, ul_sph_options *o,
                                      sph_error *err) {
  if (sph_node_child(opt, "zeta") && o->shear != UL_SHEAR_LAPLACIAN)
    return sph_node_error(sph_node_child(opt, "zeta"), err, SPH_ERR_ARG,
                          "zeta belongs to shear: laplacian");
  if (o->shear == UL_SHEAR_LAPLACIAN) {
    SPH_TRY(
        sph_node_get_double(opt, "zeta", 0, 0.7 * dim + 2.1, &o->zeta, err));
    if (!(o->zeta > 0.0))
      return sph_node_error(sph_node_child(opt, "zeta"), err, SPH_ERR_RANGE,
                            "zeta must be positive, got %g", o->zeta);
  }
  sph_node *as = sph_node_child(opt, "artificial_stress");
  if (as && o->shear != UL_SHEAR_ARTIFICIAL_STRESS)
    return sph_node_error(as, err, SPH_ERR_ARG,
                          "artificial_stress belongs to shear: "
                          "artificial-stress");
  o->as_eps = 0.3;
  o->as_n = 4.0;
  if (as) {
    static const char *const ak[] = {"epsilon", "n", NULL};
    SPH_TRY(sph_node_check_keys(as, ak, err));
    SPH_TRY(sph_node_get_double(as, "epsilon", 0, 0.3, &o->as_eps, err));
    SPH_TRY(sph_node_get_double(as, "n", 0, 4.0, &o->as_n, err));
    if (!(o->as_eps >= 0.0 && o->as_n > 0.0))
      return sph_node_error(as, err, SPH_ERR_RANGE,
                            "artificial_stress needs epsilon >= 0, n > 0");
  }
  return SPH_OK;
}

sph_status ul_sph_options_parse(sph_node *opt, int dim, ul_sph_options *o,
                                sph_error *err) {
  static const char *const keys[] = {"name",
                                     "shear",
                                     "time_stepping",
                                     "cfl",
                                     "cfl_advection",
                                     "continuity",
                                     "zeta",
                                     "artificial_stress",
                                     "dissipation",
                                     "energy",
                                     NULL};
  SPH_TRY(sph_node_check_keys(opt, keys, err));
  static const char *const shears[] = {"original", "artificial-stress",
                                       "laplacian", NULL};
  static const char *const stepping[] = {"dual", "single", NULL};
  static const char *const cont[] = {"average", "riemann", NULL};
  static const char *const diss[] = {"limited", "full", NULL};
  int sh, ts, ct, ds;
  SPH_TRY(sph_node_get_choice(opt, "shear", shears, "laplacian", &sh, err));
  /* OG and OAS as the paper ran them: single-criterion (with dual steps
   * OAS blows up on the rings within 1.5 ms) */
  SPH_TRY(sph_node_get_choice(opt, "time_stepping", stepping,
                              sh == UL_SHEAR_LAPLACIAN ? "dual" : "single", &ts,
                              err));
  SPH_TRY(sph_node_get_choice(opt, "continuity", cont, "average", &ct, err));
  o->shear = (ul_shear)sh;
  o->dual = ts == 0;
  o->pressure_term = ct == 1;
  /* full: the authors' code (SPHinXsys' dissipative Riemann solver for UL
   * solids); limited: eq. 16 as printed, which lets ENOG's shear force
   * (no potential) create energy after a rebound */
  SPH_TRY(sph_node_get_choice(opt, "dissipation", diss, "full", &ds, err));
  o->limited = ds == 0;
  /* energy.csv's strain: the work booked against the shear force (a rate
   * form), or the stored energy of the state (issue 35) */
  static const char *const energy[] = {"booked", "state", NULL};
  int en;
  SPH_TRY(sph_node_get_choice(opt, "energy", energy, "booked", &en, err));
  o->state_energy = en == 1;
  SPH_TRY(sph_node_get_double(opt, "cfl", 0, 0.4, &o->cfl_ac, err));
  if (!(o->cfl_ac > 0.0 && o->cfl_ac <= 1.0))
    return sph_node_error(sph_node_child(opt, "cfl"), err, SPH_ERR_RANGE,
                          "cfl must be in (0, 1], got %g", o->cfl_ac);
  SPH_TRY(sph_node_get_double(opt, "cfl_advection", 0, 0.2, &o->cfl_ad, err));
  if (!(o->cfl_ad > 0.0 && o->cfl_ad <= 1.0))
    return sph_node_error(sph_node_child(opt, "cfl_advection"), err,
                          SPH_ERR_RANGE,
                          "cfl_advection must be in (0, 1], "
                          "got %g",
                          o->cfl_ad);
  return shear_options_parse(opt, dim, o, err);
}
