/* The reference configuration of the Lagrangian methods (seed 000
 * sec. 3.2, seed 001 sec. 2): fixed for the total-Lagrangian ones, so the
 * neighbour lists and corrected gradients are computed once here over the
 * particles and their mirror images (images.c); ul-csph rebuilds it at each
 * reference update (sph_ref_rebuild, sph_ref_redistribute). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/corrections.h"
#include "core/tensor.h"
#include "methods/common/common_impl.h"
#include "methods/common/pair_iact.h"
#include "terms/terms_impl.h"
/* binary search for a in b's list */
sph_status sph_ref_reverse_slots(const sph_ref *ref, size_t **out,
                                 sph_error *err) {
  const sph_neighbors *nl = ref->nl;
  size_t *rev = malloc((nl->count ? nl->count : 1) * sizeof *rev);
  if (!rev)
    return sph_error_set(err, SPH_ERR_NOMEM, "reverse slots");
  sph_status st = sph_ref_reverse_fill(ref, rev, err);
  if (st != SPH_OK) {
    free(rev);
    return st;
  }
  *out = rev;
  return SPH_OK;
}

sph_status sph_ref_reverse_fill(const sph_ref *ref, size_t *rev,
                                sph_error *err) {
  const sph_neighbors *nl = ref->nl;
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
      /* a distributed run's lists ascend in the serial storage order,
       * not in the local one: then look through b's list */
      if (!(lo < nl->offset[b + 1] && nl->index[lo] == (int32_t)a))
        for (lo = nl->offset[b]; lo < nl->offset[b + 1]; ++lo)
          if (nl->index[lo] == (int32_t)a)
            break;
      if (lo < nl->offset[b + 1])
        rev[k] = lo;
      else
        ++missing;
    }
  if (missing)
    return sph_error_set(err, SPH_ERR_ARG, "neighbour lists are not symmetric");
  return SPH_OK;
}

sph_status sph_ref_ghost_slots(const sph_sim *sim, const sph_ref *ref,
                               const sph_cloud *cloud, sph_gradient_kind kind,
                               const size_t *rev, double *grad, double *lap,
                               sph_error *err) {
  if (!sim->domain)
    return SPH_OK;
  size_t ne = ref->n_ext, ni = ref->n_img, nc = SPH_CORRECTION_COEFS;
  double *coef = calloc(nc * ne + 1, sizeof *coef);
  double *part = calloc(9 * ne + 1, sizeof *part);
  sph_status st =
      coef && part
          ? sph_correction_coefficients(cloud, kind, lap != NULL, coef, err)
          : sph_error_set(err, SPH_ERR_NOMEM, "ghost coefficients");
  st = sph_domain_agree(sim->domain, st, err);
  /* the ghosts' from their owners, in parts of at most 9 */
  for (size_t j = 0; st == SPH_OK && j < nc; j += 9) {
    size_t w = nc - j < 9 ? nc - j : 9;
    for (size_t a = 0; a < ni; ++a)
      memcpy(part + w * a, coef + nc * a + j, w * sizeof *part);
    st = sph_domain_exchange(sim->domain, part, (int)w, err);
    for (size_t a = ni; st == SPH_OK && a < ne; ++a)
      memcpy(coef + nc * a + j, part + w * a, w * sizeof *part);
  }
  const sph_neighbors *nl = ref->nl;
  for (size_t a = 0; st == SPH_OK && a < ni; ++a)
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      double l;
      if (b < ni)
        continue;
      sph_correction_slot(cloud, kind, coef + nc * b, b, a, grad + 3 * rev[k],
                          &l);
      if (lap)
        lap[rev[k]] = l;
    }
  free(coef);
  free(part);
  return st;
}

/* w_ab = V_b W'(r) / r per slot and s_a = sum_b w_ab r_ab */
static void pair_weights(sph_ref *ref, const sph_kernel *kernel) {
  const sph_neighbors *nl = ref->nl;
  long ne = (long)ref->n_ext;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < ne; ++a) {
    double s[3] = {0, 0, 0};
    for (size_t k = nl->offset[a]; k < nl->offset[a + 1]; ++k) {
      size_t b = (size_t)nl->index[k];
      double r[3];
      ref_iact_pair_vector(ref->X, (size_t)a, b, r);
      double d = sqrt(sph_vec3_dot(r, r));
      ref->w[k] = d > 0.0 ? ref->V[b] * sph_kernel_dwdr(kernel, d) / d : 0.0;
      for (int c = 0; c < 3; ++c)
        s[c] += ref->w[k] * r[c];
    }
    if (a < (long)ref->n)
      memcpy(ref->s + 3 * a, s, sizeof s);
  }
}

void sph_ref_gradient(const sph_ref *ref, size_t a, size_t k, double g[3]) {
  size_t b = (size_t)ref->nl->index[k];
  double r[3];
  ref_iact_pair_vector(ref->X, a, b, r);
  for (int c = 0; c < 3; ++c)
    r[c] *= ref->w[k] / ref->V[b];
  sph_mat3_vec(ref->L + 9 * a, r, g);
}

void sph_ref_conservative_force(const sph_ref *ref, double *dp) {
  long n = (long)ref->n;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < n; ++a) {
    ref_sums s;
    sph_ref_pair_sums(ref, (size_t)a, NULL, 1, NULL, &s);
    double G[9], f[3], self[3];
    ref_sums_store(&s, G, f);
    ref_iact_force_self(ref->Qt + 9 * a, ref->s + 3 * a, self);
    for (int c = 0; c < 3; ++c)
      dp[3 * a + c] = f[c] + self[c];
  }
}

sph_status sph_ref_alloc(const sph_ref *ref, size_t ncomp, double **out,
                         sph_error *err) {
  *out = calloc(ncomp * ref->cap + 1, sizeof **out);
  return *out ? SPH_OK : sph_error_set(err, SPH_ERR_NOMEM, "state arrays");
}

/* the lists (sorted in the serial order over ranks), w's room and the
 * corrections of the points whose lists are whole */
static sph_status rebuild_local(sph_ref *ref, const sph_sim *sim,
                                sph_error *err) {
  const sph_scene *s = sim->scene;
  size_t ne = ref->n_ext;
  /* neighbours and corrected gradients in the reference configuration */
  SPH_TRY(sph_neighbors_build(ref->nl, ref->X, ne, s->dimension,
                              sim->kernel.support, ref->body,
                              SPH_PAIRS_SAME_BODY, err));
  /* a distributed run sums pairs in the serial run's order */
  if (ref->key)
    sph_domain_sort_lists_by(ref->nl, ref->n_img, ref->key);
  else
    sph_domain_sort_lists(sim->domain, ref->nl, ref->n_img);
  if (ref->nl->count + 1 > ref->w_cap) { /* grows only, amortised */
    size_t cap = 2 * (ref->nl->count + 1);
    double *w = realloc(ref->w, cap * sizeof *w);
    if (!w)
      return sph_error_set(err, SPH_ERR_NOMEM, "pair weights");
    ref->w = w;
    ref->w_cap = cap;
  }
  /* ghosts lack part of their neighbourhood: their L comes from the owner */
  size_t whole = ref->n_whole ? ref->n_whole : ref->n_img;
  /* so may the images of ghosts far from the owned particles: unused */
  size_t n = ref->n;
  int flag = sim->domain && !ref->n_whole && ref->n_img > n;
  if (flag && ref->n_img > ref->partial_cap) { /* grows only */
    unsigned char *p = realloc(ref->partial, ref->n_img);
    if (!p)
      return sph_error_set(err, SPH_ERR_NOMEM, "mirror images");
    ref->partial = p;
    ref->partial_cap = ref->n_img;
  }
  const sph_neighbors *nl = ref->nl;
  long ni = flag ? (long)ref->n_img : 0;
#pragma omp parallel for schedule(static)
  for (long a = 0; a < ni; ++a) {
    int near = a < (long)n;
    for (size_t k = nl->offset[a]; !near && k < nl->offset[a + 1]; ++k)
      near = (size_t)nl->index[k] < n;
    ref->partial[a] = (unsigned char)!near;
  }
  sph_cloud cloud = {.n = sim->domain ? whole : ne,
                     .partial = flag ? ref->partial : NULL,
                     .dim = s->dimension,
                     .x = ref->X,
                     .volume = ref->V,
                     .id = ref->id,
                     .nl = ref->nl,
                     .kernel = &sim->kernel};
  return sph_correction_gradient(&cloud, SPH_GRAD_CORRECTED, NULL, NULL, ref->L,
                                 err);
}

sph_status sph_ref_rebuild(sph_ref *ref, const sph_sim *sim, sph_error *err) {
  /* a rank that fails alone must not leave the others in the exchange */
  SPH_TRY(sph_domain_agree(sim->domain, rebuild_local(ref, sim, err), err));
  SPH_TRY(sph_domain_exchange(sim->domain, ref->L, 9, err));
  pair_weights(ref, &sim->kernel);
  return SPH_OK;
}

sph_status sph_ref_redistribute(sph_ref *ref, sph_sim *sim, sph_error *err) {
  sph_particles *ps = sim->ps;
  if (!sim->domain || sim->method->distributed != SPH_DISTRIBUTED_DYNAMIC)
    return SPH_OK;
  SPH_TRY(sph_domain_rebuild(sim->domain, ps, sim->kernel.support, err));
  const sph_scene *s = sim->scene;
  ref->n = ref->n_img = ps->n;
  ref->n_ext = ps->n + sph_domain_ghosts(sim->domain);
  for (size_t a = 0; a < ref->n_ext; ++a) {
    const sph_body *b = &s->bodies[ps->body[a]];
    ref->body[a] = ps->body[a];
    ref->id[a] = ps->id[a];
    ref->mat[a] = &s->materials[b->material];
    ref->rho0[a] = ref->mat[a]->density;
    if (ref->axes)
      ref->axes[a] = b->transform.given ? b->transform.R : NULL;
  }
  return sph_sim_terms_renumber(sim, err);
}

sph_status sph_ref_create(sph_ref *ref, sph_sim *sim, int images,
                          sph_error *err) {
  memset(ref, 0, sizeof *ref);
  const sph_scene *s = sim->scene;
  sph_particles *ps = sim->ps;
  int timer = sph_sim_add_timer(sim, "corrections");
  double t0 = sph_wtime();
  SPH_TRY(sph_images_build(ref, sim, images, err));
  size_t n = ref->n, ne = ref->n_ext;
  if (ref->n_img > n)
    sim->mirror = &ref->mirror;

  /* per-point material and density, the fastest wave */
  ref->mat = malloc(ref->cap * sizeof *ref->mat);
  ref->rho0 = malloc(ref->cap * sizeof *ref->rho0);
  if (!ref->mat || !ref->rho0)
    return sph_error_set(err, SPH_ERR_NOMEM, "materials");
  for (size_t a = 0; a < ne; ++a) {
    ref->mat[a] = &s->materials[s->bodies[ref->body[a]].material];
    ref->rho0[a] = ref->mat[a]->density;
  }
  int placed = 0;
  for (size_t b = 0; b < s->nbodies; ++b) {
    double c = sph_material_wave_speed(&s->materials[s->bodies[b].material]);
    ref->cp = c > ref->cp ? c : ref->cp;
    placed |= s->bodies[b].transform.given;
  }
  /* the material axes of placed bodies turn with them */
  if (placed &&
      !(ref->axes = malloc((ref->cap ? ref->cap : 1) * sizeof *ref->axes)))
    return sph_error_set(err, SPH_ERR_NOMEM, "materials");
  for (size_t a = 0; placed && a < n; ++a) {
    const sph_transform *T = &s->bodies[ref->body[a]].transform;
    ref->axes[a] = T->given ? T->R : NULL;
  }

  /* state and output fields */
  static const sph_field need[] = {SPH_FIELD_POSITION,  SPH_FIELD_MOMENTUM,
                                   SPH_FIELD_DEFGRAD,   SPH_FIELD_JACOBIAN,
                                   SPH_FIELD_PK1,       SPH_FIELD_DISPLACEMENT,
                                   SPH_FIELD_STRESS,    SPH_FIELD_PRESSURE,
                                   SPH_FIELD_VON_MISES, SPH_FIELD_MASS};
  for (size_t i = 0; i < sizeof need / sizeof *need; ++i)
    SPH_TRY(sph_particles_require(ps, need[i], err));
  for (int i = 0; i < s->output.nfields; ++i)
    if (s->output.fields[i] == SPH_FIELD_ACCELERATION)
      SPH_TRY(sph_particles_require(ps, SPH_FIELD_ACCELERATION, err));
  ref->owns_state = ne > n || ref->all_images;
  if (ref->owns_state) {
    SPH_TRY(sph_ref_alloc(ref, 3, &ref->x, err));
    SPH_TRY(sph_ref_alloc(ref, 3, &ref->p, err));
    SPH_TRY(sph_ref_alloc(ref, 9, &ref->F, err));
    SPH_TRY(sph_ref_alloc(ref, 1, &ref->J, err));
    SPH_TRY(sph_ref_alloc(ref, 9, &ref->P, err));
  } else {
    ref->x = ps->field[SPH_FIELD_POSITION];
    ref->p = ps->field[SPH_FIELD_MOMENTUM];
    ref->F = ps->field[SPH_FIELD_DEFGRAD];
    ref->J = ps->field[SPH_FIELD_JACOBIAN];
    ref->P = ps->field[SPH_FIELD_PK1];
  }
  /* a reference's initial state comes deformed (reference.h) */
  const double *x0 =
      sim->initial_defgrad ? ps->field[SPH_FIELD_POSITION] : ref->X;
  for (size_t a = 0; a < n; ++a) {
    if (ref->x != x0)
      memcpy(ref->x + 3 * a, x0 + 3 * a, 3 * sizeof(double));
    for (int c = 0; c < 3; ++c)
      ref->p[3 * a + c] =
          ref->rho0[a] * ps->field[SPH_FIELD_VELOCITY][3 * a + c];
    if (sim->initial_defgrad)
      memcpy(ref->F + 9 * a, ps->field[SPH_FIELD_DEFGRAD] + 9 * a,
             9 * sizeof(double));
    else
      sph_mat3_identity(ref->F + 9 * a);
    ref->J[a] = sph_mat3_det(ref->F + 9 * a);
    ps->field[SPH_FIELD_MASS][a] = ref->rho0[a] * ref->V[a];
  }
  sph_mirror_state(ref, ref->x, ref->p, ref->F, NULL, ref->J);

  int64_t *id = malloc(ref->cap * sizeof *id);
  if (!id)
    return sph_error_set(err, SPH_ERR_NOMEM, "ids");
  for (size_t a = 0; a < ne; ++a) { /* an image's is its source's */
    size_t r = (size_t)ref->src[a];
    id[a] =
        r < n ? ps->id[r] : sph_domain_ghost_id(sim->domain)[r - ref->n_img];
  }
  ref->id = id;
  ref->s = calloc(3 * ref->cap + 3, sizeof *ref->s);
  if (!ref->s)
    return sph_error_set(err, SPH_ERR_NOMEM, "pair weights");
  SPH_TRY(sph_ref_alloc(ref, 9, &ref->L, err));
  SPH_TRY(sph_ref_alloc(ref, 9, &ref->Qt, err));
  SPH_TRY(sph_neighbors_create(&ref->nl, err));
  sph_status st = sph_ref_rebuild(ref, sim, err);
  sim->timers[timer].seconds += sph_wtime() - t0;
  sim->timers[timer].calls++;
  return st;
}

void sph_ref_destroy(sph_ref *ref) {
  sph_neighbors_destroy(ref->nl);
  free(ref->id);
  free(ref->w);
  free(ref->partial);
  free(ref->L);
  free(ref->s);
  free(ref->Qt);
  free(ref->mat);
  free(ref->rho0);
  free(ref->X);
  free(ref->V);
  free(ref->body);
  free(ref->src);
  free(ref->vsign);
  free(ref->rsign);
  free(ref->ssign);
  free(ref->vmat);
  free(ref->key);
  free(ref->axes);
  if (ref->all_images) {
    free(ref->all_images->src);
    free(ref->all_images->vsign);
    free(ref->all_images->rsign);
    free(ref->all_images->ssign);
    free(ref->all_images->vmat);
    free(ref->all_images->X);
    free(ref->all_images);
  }
  if (ref->owns_state) {
    free(ref->x);
    free(ref->p);
    free(ref->F);
    free(ref->J);
    free(ref->P);
  }
  memset(ref, 0, sizeof *ref);
}
