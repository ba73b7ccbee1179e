/* Shared set-up and output of the total-Lagrangian methods (seed 000
 * sec. 3.2, seed 001 sec. 2): the reference configuration is fixed, so the
 * neighbour lists and corrected gradients are computed once here. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "methods/tl_common_impl.h"
#include "sph/corrections.h"
#include "sph/tensor.h"

/* slot of (b -> a) for every slot (a -> b): binary search in b's list */
static sph_status reverse_slots(tl_reference *ref, sph_error *err) {
  const sph_neighbors *nl = ref->nl;
  ref->rev = malloc((nl->count ? nl->count : 1) * sizeof *ref->rev);
  if (!ref->rev)
    return sph_error_set(err, SPH_ERR_NOMEM, "reverse slots");
  long n = (long)nl->n, missing = 0;
#pragma omp parallel for schedule(static) reduction(+ : missing)
  for (long a = 0; a < n; ++a)
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      size_t lo = nl->offset[b], hi = nl->offset[b + 1];
      while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (nl->index[mid] < (int32_t)a)
          lo = mid + 1;
        else
          hi = mid;
      }
      if (lo < nl->offset[b + 1] && nl->index[lo] == (int32_t)a)
        ref->rev[k] = lo;
      else
        ++missing;
    }
  if (missing)
    return sph_error_set(err, SPH_ERR_ARG,
                         "neighbour lists are not "
                         "symmetric");
  return SPH_OK;
}

sph_status tl_reference_create(tl_reference *ref, sph_sim *sim,
                               sph_error *err) {
  memset(ref, 0, sizeof *ref);
  const sph_scene *s = sim->scene;
  sph_particles *ps = sim->ps;
  size_t n = ps->n;

  /* per-particle material and density, the fastest wave */
  ref->mat = malloc((n ? n : 1) * sizeof *ref->mat);
  ref->rho0 = malloc((n ? n : 1) * sizeof *ref->rho0);
  if (!ref->mat || !ref->rho0)
    return sph_error_set(err, SPH_ERR_NOMEM, "materials");
  for (size_t a = 0; a < n; ++a) {
    ref->mat[a] = &s->materials[s->bodies[ps->body[a]].material];
    ref->rho0[a] = ref->mat[a]->density;
  }
  for (size_t b = 0; b < s->nbodies; ++b) {
    double c = sph_material_wave_speed(&s->materials[s->bodies[b].material]);
    ref->cp = c > ref->cp ? c : ref->cp;
  }

  /* state and output fields, in the reference state */
  static const sph_field need[] = {SPH_FIELD_POSITION,  SPH_FIELD_MOMENTUM,
                                   SPH_FIELD_DEFGRAD,   SPH_FIELD_JACOBIAN,
                                   SPH_FIELD_PK1,       SPH_FIELD_DISPLACEMENT,
                                   SPH_FIELD_STRESS,    SPH_FIELD_PRESSURE,
                                   SPH_FIELD_VON_MISES, SPH_FIELD_MASS};
  for (size_t i = 0; i < sizeof need / sizeof *need; ++i)
    SPH_TRY(sph_particles_require(ps, need[i], err));
  for (size_t a = 0; a < n; ++a) {
    memcpy(ps->field[SPH_FIELD_POSITION] + 3 * a,
           ps->field[SPH_FIELD_POSITION0] + 3 * a, 3 * sizeof(double));
    for (int c = 0; c < 3; ++c)
      ps->field[SPH_FIELD_MOMENTUM][3 * a + c] =
          ref->rho0[a] * ps->field[SPH_FIELD_VELOCITY][3 * a + c];
    sph_mat3_identity(ps->field[SPH_FIELD_DEFGRAD] + 9 * a);
    ps->field[SPH_FIELD_JACOBIAN][a] = 1.0;
    ps->field[SPH_FIELD_MASS][a] =
        ref->rho0[a] * ps->field[SPH_FIELD_VOLUME0][a];
  }

  /* neighbours and corrected gradients in the reference configuration */
  int timer = sph_sim_add_timer(sim, "corrections");
  double t0 = sph_wtime();
  SPH_TRY(sph_neighbors_create(&ref->nl, err));
  SPH_TRY(sph_neighbors_build(ref->nl, ps->field[SPH_FIELD_POSITION0], n,
                              s->dimension, sim->kernel.support, ps->body,
                              SPH_PAIRS_SAME_BODY, err));
  SPH_TRY(reverse_slots(ref, err));
  sph_cloud cloud = {.n = n,
                     .dim = s->dimension,
                     .x = ps->field[SPH_FIELD_POSITION0],
                     .volume = ps->field[SPH_FIELD_VOLUME0],
                     .id = ps->id,
                     .nl = ref->nl,
                     .kernel = &sim->kernel};
  ref->grad = calloc(3 * ref->nl->count + 3, sizeof *ref->grad);
  if (!ref->grad)
    return sph_error_set(err, SPH_ERR_NOMEM, "corrected gradients");
  SPH_TRY(sph_correction_gradient(&cloud, SPH_GRAD_CORRECTED, ref->grad, NULL,
                                  NULL, err));
  sim->timers[timer].seconds += sph_wtime() - t0;
  sim->timers[timer].calls++;
  return SPH_OK;
}

void tl_reference_destroy(tl_reference *ref) {
  sph_neighbors_destroy(ref->nl);
  free(ref->grad);
  free(ref->rev);
  free(ref->mat);
  free(ref->rho0);
  memset(ref, 0, sizeof *ref);
}

void tl_derive(sph_sim *sim, const tl_reference *ref, const double *x,
               const double *p, const double *F, const double *J,
               const double *P) {
  sph_particles *ps = sim->ps;
  long n = (long)ps->n;
  const double *X = ps->field[SPH_FIELD_POSITION0];
  double *v = ps->field[SPH_FIELD_VELOCITY];
  double *u = ps->field[SPH_FIELD_DISPLACEMENT];
  double *Jf = ps->field[SPH_FIELD_JACOBIAN];
  double *sig = ps->field[SPH_FIELD_STRESS];
  double *pr = ps->field[SPH_FIELD_PRESSURE];
  double *vm = ps->field[SPH_FIELD_VON_MISES];
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    for (int c = 0; c < 3; ++c) {
      v[3 * a + c] = p[3 * a + c] / ref->rho0[a];
      u[3 * a + c] = x[3 * a + c] - X[3 * a + c];
    }
    double detF = sph_mat3_det(F + 9 * a);
    if (Jf != J)
      Jf[a] = J ? J[a] : detF;
    /* Cauchy stress sigma = P F^T / det F */
    double Ft[9], S[9];
    sph_mat3_transpose(F + 9 * a, Ft);
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

void tl_energy(sph_sim *sim, const tl_reference *ref, const double *p,
               const double *F, const double *H, const double *J,
               double *kinetic, double *strain) {
  const double *V = sim->ps->field[SPH_FIELD_VOLUME0];
  double ek = 0.0, es = 0.0;
  for (size_t a = 0; a < sim->ps->n; ++a) {
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
}
