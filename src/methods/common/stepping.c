/* The time-stepping glue of the Lagrangian methods (methods/common): the
 * terms' rates and constraints on the state of sph_ref, leap-frog and
 * Runge-Kutta steps with the finite-state check, the stable step of seed
 * 000 eq. 44, the derived output fields and the energy. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/tensor.h"
#include "methods/common/common_impl.h"
#include "terms/terms_impl.h"

void sph_ref_derive(sph_sim *sim, const sph_ref *ref, const double *H,
                    const double *J, const double *Fs) {
  sph_particles *ps = sim->ps;
  long n = (long)ps->n;
  const double *X = ps->field[SPH_FIELD_POSITION0];
  const double *x = ref->x, *p = ref->p, *F = ref->F, *P = ref->P;
  double *v = ps->field[SPH_FIELD_VELOCITY];
  double *u = ps->field[SPH_FIELD_DISPLACEMENT];
  double *Jf = ps->field[SPH_FIELD_JACOBIAN];
  double *sig = ps->field[SPH_FIELD_STRESS];
  double *pr = ps->field[SPH_FIELD_PRESSURE];
  double *vm = ps->field[SPH_FIELD_VON_MISES];
  if (ref->owns_state) {
    memcpy(ps->field[SPH_FIELD_POSITION], x, 3 * (size_t)n * sizeof *x);
    memcpy(ps->field[SPH_FIELD_MOMENTUM], p, 3 * (size_t)n * sizeof *p);
    memcpy(ps->field[SPH_FIELD_DEFGRAD], F, 9 * (size_t)n * sizeof *F);
    memcpy(ps->field[SPH_FIELD_PK1], P, 9 * (size_t)n * sizeof *P);
  }
  (void)H;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    for (int c = 0; c < 3; ++c) {
      v[3 * a + c] = p[3 * a + c] / ref->rho0[a];
      u[3 * a + c] = x[3 * a + c] - X[3 * a + c];
    }
    const double *Fa = (Fs ? Fs : F) + 9 * a;
    double detF = sph_mat3_det(Fa);
    Jf[a] = J ? J[a] : detF;
    /* Cauchy stress sigma = P F^T / det F */
    double Ft[9], S[9];
    sph_mat3_transpose(Fa, Ft);
    sph_mat3_mul(P + 9 * a, Ft, S);
    for (int k = 0; k < 9; ++k)
      S[k] /= detF;
    memcpy(sig + 9 * a, S, sizeof S);
    double mean = sph_mat3_trace(S) / 3.0, dev2 = 0.0;
    pr[a] = mean;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double d = S[3 * i + j] - (i == j) * mean;
        dev2 += d * d;
      }
    vm[a] = sqrt(1.5 * dev2);
  }
}

double sph_ref_max_wave_speed(const sph_ref *ref, const double *F) {
  long n = (long)ref->n;
  double c2max = 0.0;
#pragma omp parallel for schedule(static) reduction(max : c2max)
  for (long a = 0; a < n; ++a) {
    const double *Fa = F + 9 * a;
    const sph_material *m = ref->mat[a];
    double Q[27], Fb[9], T[9];
    if (ref->axes && ref->axes[a]) { /* F in the body frame: R^T F R */
      const double *R = ref->axes[a];
      sph_mat3_mul(Fa, R, T);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          Fb[3 * i + j] =
              R[i] * T[j] + R[3 + i] * T[3 + j] + R[6 + i] * T[6 + j];
      Fa = Fb;
    }
    sph_material_acoustic_tensors(m, Fa, Q);
    for (int d = 0; d < 3; ++d) {
      double lo, hi;
      sph_mat3_sym_extremes(Q + 9 * d, &lo, &hi);
      double c2 = hi / m->density;
      c2max = c2 > c2max ? c2 : c2max;
    }
  }
  return sqrt(c2max);
}

double sph_ref_stable_dt(const sph_ref *ref, const sph_sim *sim, double cfl,
                         int current) {
  double c = ref->cp;
  if (current) {
    double cs = sph_ref_max_wave_speed(ref, ref->F);
    c = cs > c ? cs : c;
  }
  return cfl * sim->dp / c;
}

sph_status sph_ref_check_finite(const sph_ref *ref, sph_error *err) {
  long n3 = 3 * (long)ref->n, first = n3;
  /* the lowest non-finite entry, whatever the thread count */
#pragma omp parallel for schedule(static) reduction(min : first)
  for (long i = 0; i < n3; ++i)
    if (!isfinite(ref->p[i]) || !isfinite(ref->x[i]))
      first = i < first ? i : first;
  if (first < n3)
    return sph_error_set(err, SPH_ERR_NUMERIC,
                         "nan: non-finite state at particle %ld", first / 3);
  return SPH_OK;
}

void sph_ref_energy(sph_sim *sim, const sph_ref *ref, const double *H,
                    const double *J, double *kinetic, double *strain) {
  const double *V = ref->V, *p = ref->p, *F = ref->F;
  double ek = 0.0, es = 0.0;
  for (size_t a = 0; a < ref->n; ++a) {
    double Ha[9];
    const double *Fa = F + 9 * a;
    if (H)
      memcpy(Ha, H + 9 * a, sizeof Ha);
    else
      sph_mat3_cofactor(Fa, Ha);
    double Ja = J ? J[a] : sph_mat3_det(Fa);
    ek += V[a] * sph_vec3_dot(p + 3 * a, p + 3 * a) / (2 * ref->rho0[a]);
    es += V[a] * sph_material_energy(ref->mat[a], Fa, Ha, Ja);
  }
  *kinetic = ek;
  *strain = es;
  (void)sim;
}

void sph_ref_acceleration(sph_sim *sim, const sph_ref *ref, const double *dp) {
  double *acc = sim->ps->field[SPH_FIELD_ACCELERATION];
  long n = (long)ref->n;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a)
    for (int c = 0; c < 3; ++c)
      acc[3 * a + c] = dp[3 * a + c] / ref->rho0[a];
}

sph_status sph_step_leapfrog_options(sph_node *opt, double *cfl,
                                     sph_error *err) {
  SPH_TRY(sph_node_get_double(opt, "cfl", 0, 0.3, cfl, err));
  if (!(*cfl > 0.0 && *cfl <= 1.0))
    return sph_node_error(sph_node_child(opt, "cfl"), err, SPH_ERR_RANGE,
                          "cfl must be in (0, 1], got %g", *cfl);
  const char *integ;
  SPH_TRY(sph_node_get_string(opt, "integrator", 0, "leapfrog", &integ, err));
  if (strcmp(integ, "leapfrog"))
    return sph_node_error(sph_node_child(opt, "integrator"), err, SPH_ERR_RANGE,
                          "'%s' is not one of: leapfrog", integ);
  return SPH_OK;
}

sph_status sph_step_leapfrog_attach(
    sph_sim *sim, const sph_ref *ref, sph_leapfrog *lf, double *dp,
    sph_status (*rates)(void *ctx, double t, sph_error *err),
    sph_status (*constrain)(void *ctx, double t, sph_error *err), void *ctx,
    sph_error *err) {
  *lf = (sph_leapfrog){.n = ref->n,
                       .x = ref->x,
                       .p = ref->p,
                       .dp = dp,
                       .rho0 = ref->rho0,
                       .rates = rates,
                       .constrain = constrain,
                       .ctx = ctx};
  SPH_TRY(sph_step_external_terms(sim, ref, err));
  return sph_step_essential_bc(sim, ref, constrain, ctx, err);
}

sph_status sph_step_external_terms(sph_sim *sim, const sph_ref *ref,
                                   sph_error *err) {
  if (sim->scene->has_body_force)
    SPH_TRY(body_force_create(sim, ref->rho0, err));
  if (sim->scene->contact.given)
    SPH_TRY(contact_create(sim, ref->rho0, err));
  return SPH_OK;
}

sph_status sph_step_essential_bc(sph_sim *sim, const sph_ref *ref,
                                 sph_status (*constrain)(void *ctx, double t,
                                                         sph_error *err),
                                 void *ctx, sph_error *err) {
  if (!sph_scene_has_essential_bc(sim->scene))
    return SPH_OK;
  SPH_TRY(essential_bc_create(sim, ref->rho0, err));
  /* the initial state honours the constraints */
  return constrain(ctx, 0.0, err);
}

/* the finite-state check after an integrator step, timed with the step */
static sph_status step_checked(sph_sim *sim, const sph_ref *ref, int timer,
                               double integrator_seconds, sph_error *err) {
  double t0 = sph_wtime();
  sph_status st = sph_ref_check_finite(ref, err);
  sph_timer *tm = &sim->timers[timer];
  tm->seconds += integrator_seconds + sph_wtime() - t0;
  tm->calls++;
  return st;
}

sph_status sph_step_leapfrog(sph_sim *sim, const sph_ref *ref, sph_leapfrog *lf,
                             int timer, double dt, sph_error *err) {
  double s0 = lf->seconds;
  SPH_TRY(sph_leapfrog_step(lf, sim->t, dt, err));
  return step_checked(sim, ref, timer, lf->seconds - s0, err);
}

sph_status sph_step_leapfrog_derive(sph_sim *sim, const sph_ref *ref,
                                    sph_leapfrog *lf, const double *dp,
                                    sph_error *err) {
  sph_ref_derive(sim, ref, NULL, NULL, NULL);
  if (sim->ps->field[SPH_FIELD_ACCELERATION]) {
    if (!lf->have_rates)
      SPH_TRY(lf->rates(lf->ctx, sim->t, err));
    sph_ref_acceleration(sim, ref, dp);
  }
  return SPH_OK;
}

sph_status sph_step_rates_terms(sph_sim *sim, const sph_ref *ref, double *dp,
                                int timer, double t0, double t,
                                sph_error *err) {
  sim->timers[timer].seconds += sph_wtime() - t0;
  sim->timers[timer].calls++;
  sph_stage s = {.t = t,
                 .x = ref->x,
                 .p = ref->p,
                 .F = ref->F,
                 .x_moment = ref->x,
                 .dp = dp};
  return sph_sim_terms_rates(sim, &s, err);
}

sph_status sph_step_constrain_terms(sph_sim *sim, const sph_ref *ref, double t,
                                    sph_error *err) {
  sph_stage s = {.t = t, .x = ref->x, .p = ref->p, .F = ref->F};
  return sph_sim_terms_constrain(sim, &s, err);
}

sph_status sph_step_rk(sph_sim *sim, const sph_ref *ref, sph_ode *ode,
                       sph_rk_step integrate, int timer, double dt,
                       sph_error *err) {
  double s0 = ode->seconds;
  SPH_TRY(integrate(ode, sim->t, dt, err));
  return step_checked(sim, ref, timer, ode->seconds - s0, err);
}

sph_status sph_step_rk_acceleration(sph_sim *sim, const sph_ref *ref,
                                    sph_ode *ode, sph_error *err) {
  if (!sim->ps->field[SPH_FIELD_ACCELERATION])
    return SPH_OK;
  /* the rates are scratch between steps; the momentum's are the second */
  SPH_TRY(ode->rhs(ode->ctx, 0, sim->t, 0.0, err));
  sph_ref_acceleration(sim, ref, ode->rate[1]);
  return SPH_OK;
}

int sph_step_state_xpF(const sph_ref *ref, sph_state_array *out) {
  out[0] = (sph_state_array){"x", ref->x, 3 * ref->n};
  out[1] = (sph_state_array){"p", ref->p, 3 * ref->n};
  out[2] = (sph_state_array){"F", ref->F, 9 * ref->n};
  return 3;
}

sph_status sph_step_leapfrog_restore(sph_sim *sim, sph_leapfrog *lf,
                                     sph_error *err) {
  SPH_TRY(lf->rates(lf->ctx, sim->t, err));
  lf->have_rates = 1;
  return SPH_OK;
}
