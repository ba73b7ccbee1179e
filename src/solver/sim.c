/* The simulation object and its time step: particles from the scene, the
 * method from the registry, the terms the method created (docs/design.md sec.
 * 2, 4). The loop calls method->stable_dt and method->step once per step. */
#include "solver/sim.h"

#include "core/check.h"
#include "core/tensor.h"
#include "gpu/gpu.h"
#include "parallel/domain.h"
#include "scene/cloud.h"
#include "scene/geometry.h"
#include "scene/node.h"
#include "solver/memory.h"
#include "solver/reference.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A singular moment matrix names its particle by id and position
 * (src/core/corrections.c); the error gains the particle's body and is
 * placed at that body's entry in the scene file. */
static void blame_singular(const sph_sim *sim, sph_error *err) {
  const char *at = err ? strstr(err->message, "at particle ") : NULL;
  long long id;
  if (!at || err->code != SPH_ERR_SINGULAR || sscanf(at + 12, "%lld", &id) != 1)
    return;
  const sph_particles *ps = sim->ps;
  const sph_scene *s = sim->scene;
  for (size_t a = 0; a < ps->n; ++a)
    if (ps->id[a] == id && ps->body[a] >= 0 &&
        (size_t)ps->body[a] < s->nbodies) {
      const sph_body *b = &s->bodies[ps->body[a]];
      char msg[sizeof err->message];
      snprintf(msg, sizeof msg, "%s", err->message);
      sph_error_at(err, err->code, s->path, b->line, b->col, NULL,
                   "body %s: %s", b->name, msg);
      return;
    }
}

/* The node of an output.fields / probe fields entry naming `name`, or the
 * list itself. */
static const sph_node *field_node(const sph_node *list, const char *name) {
  for (size_t i = 0; list && i < list->count; ++i)
    if (list->items[i]->value && !strcmp(list->items[i]->value, name))
      return list->items[i];
  return list;
}

/* Every field an output asks for is one the method fills (its ops table's
 * `fields`); else the request is refused at its key with the method's list
 * (a field would otherwise be left out of the files without a word). */
static sph_status check_output_fields(const sph_sim *sim, sph_error *err) {
  const sph_scene *s = sim->scene;
  const sph_output *o = &s->output;
  const sph_node *out = sph_node_child(s->root, "output");
  char have[512] = "";
  for (int f = 0; f < SPH_FIELD_COUNT; ++f)
    if (sim->method->fields & 1ul << f) {
      strncat(have, have[0] ? ", " : "", sizeof have - strlen(have) - 1);
      strncat(have, sph_field_name((sph_field)f),
              sizeof have - strlen(have) - 1);
    }
  for (size_t k = 0; k <= o->nprobes + 1; ++k) {
    const int *fields = NULL;
    int n = 0;
    const sph_node *at = NULL;
    if (k == 0) { /* output.fields */
      fields = o->fields, n = o->nfields;
      at = out ? sph_node_child(out, "fields") : NULL;
    } else if (k == 1) { /* the frames' colour */
      fields = o->png.enabled ? &o->png.color_field : NULL, n = fields != NULL;
      const sph_node *png = out ? sph_node_child(out, "png") : NULL;
      at = png ? sph_node_child(png, "color") : NULL;
      at = at ? at : png;
    } else { /* a probe */
      fields = o->probes[k - 2].fields, n = o->probes[k - 2].nfields;
      const sph_node *pr = out ? sph_node_child(out, "probes") : NULL;
      at = pr && k - 2 < pr->count ? sph_node_child(pr->items[k - 2], "fields")
                                   : pr;
    }
    for (int i = 0; i < n; ++i) {
      if (sim->method->fields & 1ul << fields[i])
        continue;
      const char *name = sph_field_name((sph_field)fields[i]);
      const sph_node *node = k == 1 ? at : field_node(at, name);
      node = node ? node : (out ? out : s->root);
      return sph_node_error(node, err, SPH_ERR_ARG,
                            "%s does not provide the field '%s' (it provides "
                            "%s)",
                            sim->method->name, name, have);
    }
  }
  return SPH_OK;
}

/* Refuses, before anything is allocated, a run that would not fit in the
 * memory it may take (solver/memory.h: --max-memory, the memory available,
 * the memory cgroup, ulimit -v): particles bounded from the bodies' lattices,
 * each with about 1.8 kB of fields and buffers and 24 bytes per neighbour
 * slot, and the png sink's frame buffers (SPH_PNG_BYTES_PER_PIXEL a frame,
 * and over ranks each rank's tag attachment, SPH_PNG_TAG_BYTES_PER_PIXEL).
 * The per-particle figures are an upper bound fitted to the growth of peak
 * RSS (/usr/bin/time, one thread, two frames) with the particle count:
 * twisting_column (tl-jst 3D, 1.8k/20k/100k particles) 3.40 kB, colliding_rings
 * (ul-sph 2D, 4.4k/17.6k) 2.12 kB, punch (3D, 0.7k/18.7k) 1.82 kB; the
 * former 1 kB + 24 nb gave 2.77 and 1.51 kB, low by 25 and 40 %
 * (tests/cli/run_memory_tests.sh holds the estimate above the peak).
 */
static sph_status check_memory(const sph_scene *scene, double support,
                               double dp, sph_error *err) {
  int dim = scene->dimension;
  double n = 0.0;
  for (size_t b = 0; b < scene->nbodies; ++b) {
    const sph_body *bd = &scene->bodies[b];
    double lo[3], hi[3], k = 1.0;
    if (bd->shape.kind == SPH_SHAPE_PARTICLES) { /* read: known */
      n += (double)bd->shape.cloud->n;
      continue;
    }
    sph_shape_bounds(&bd->shape, dim, lo, hi);
    for (int c = 0; c < dim; ++c)
      k *= bd->lattice == SPH_LATTICE_FACES
               ? (double)bd->count[c]
               : floor((hi[c] - lo[c]) / bd->spacing) + 1.0;
    n += k;
  }
  double r = support / dp, nb = dim == 3 ? 4.19 * r * r * r : 3.14 * r * r;
  /* over ranks: the share of the ranks on this node */
  int ranks = sph_domain_world_size(), here = sph_domain_node_size();
  double need = n * (1800.0 + 24.0 * nb) * here / ranks;
  double frame = 0.0;
  if (scene->output.png.enabled) {
    double px =
        (double)scene->output.png.width * (double)scene->output.png.height;
    frame = px * SPH_PNG_BYTES_PER_PIXEL;
    if (ranks > 1)
      frame =
          here * px * (SPH_PNG_BYTES_PER_PIXEL + SPH_PNG_TAG_BYTES_PER_PIXEL);
  }
  sph_memory_limit lim;
  sph_memory_limit_get(scene->memory_limit, &lim);
  if (!(lim.bytes > 0.0) || need + frame <= lim.bytes)
    return SPH_OK;
  const sph_node *bodies = sph_node_child(scene->root, "bodies");
  const sph_node *at = bodies ? bodies : scene->root;
  char share[96] = "";
  if (ranks > 1)
    snprintf(share, sizeof share, " (%d of the %d ranks on this node)", here,
             ranks);
  if (frame > 0.0 && (frame > need || frame > lim.bytes)) {
    const sph_node *out = sph_node_child(scene->root, "output");
    const sph_node *png = out ? sph_node_child(out, "png") : NULL;
    return sph_node_error(
        png ? png : at, err, SPH_ERR_RANGE,
        "the %d x %d frames need about %.3g GB%s and the particles about "
        "%.3g GB; %s: smaller frames (png.width, png.height)",
        scene->output.png.width, scene->output.png.height, frame / 1e9, share,
        need / 1e9, lim.what);
  }
  return sph_node_error(at, err, SPH_ERR_RANGE,
                        "about %.3g particles need about %.3g GB%s; %s: fewer "
                        "particles (a larger spacing or count)",
                        n, (need + frame) / 1e9, share, lim.what);
}

/* A distributed run (more than one MPI rank) of what runs distributed so
 * far: refused, the same on every rank, before anything is written; from
 * each rank's share (gidx: its storage indices, of N). */
static sph_status distribute(sph_sim *sim, const int64_t *gidx, size_t N,
                             sph_error *err) {
  const sph_scene *s = sim->scene;
  const sph_node *bcs = sph_node_child(s->root, "boundaries");
  if (!sim->method->distributed) {
    const sph_node *name = sph_node_child(s->method, "name");
    char runs[256] = ""; /* the methods that do, from the registry */
    for (const sph_method_ops *const *m = sph_method_list(); *m; ++m)
      if ((*m)->distributed) {
        strncat(runs, runs[0] ? ", " : "", sizeof runs - strlen(runs) - 1);
        strncat(runs, (*m)->name, sizeof runs - strlen(runs) - 1);
      }
    return sph_node_error(name ? name : s->method, err, SPH_ERR_UNSUPPORTED,
                          "%s does not run over MPI ranks yet (these do: "
                          "%s); run it without mpirun",
                          sim->method->name, runs);
  }
  /* the planes' mirror images need the ghosts of their sources */
  sph_domain_plane planes[32];
  int np = 0;
  for (size_t k = 0; k < s->nboundaries; ++k) {
    const sph_boundary *bc = &s->boundaries[k];
    if (bc->kind != SPH_BC_SYMMETRY && bc->kind != SPH_BC_SKEW_SYMMETRY)
      continue;
    if (np == (int)(sizeof planes / sizeof *planes))
      return sph_node_error(bcs && k < bcs->count ? bcs->items[k] : s->root,
                            err, SPH_ERR_UNSUPPORTED,
                            "more than %d symmetry planes do not run over "
                            "MPI ranks; run without mpirun",
                            np);
    planes[np] =
        (sph_domain_plane){.at = bc->select.at, .axis = bc->select.axis};
    memcpy(planes[np++].n, bc->select.normal, sizeof planes->n);
  }
  /* updated Lagrangian: ghosts within three supports of the box and its
   * reflections, as an image's stabilised force matrix reads its
   * neighbours' corrections (methods/ul_csph) */
  int dynamic = sim->method->distributed == SPH_DISTRIBUTED_DYNAMIC;
  if (np && dynamic) {
    SPH_TRY(sph_domain_create_share(&sim->domain, &sim->ps, gidx, N,
                                    sim->kernel.support, 1, err));
    return sph_domain_dyn_mirror(sim->domain, planes, np, 3.0, err);
  }
  if (np)
    return sph_domain_create_share_mirrored(
        &sim->domain, &sim->ps, gidx, N, sim->kernel.support, planes, np, err);
  return sph_domain_create_share(&sim->domain, &sim->ps, gidx, N,
                                 sim->kernel.support, dynamic, err);
}

/* Whether each rank can build its own share of the particles without the
 * whole set (sph_scene_build_share): every distributed method, symmetry
 * planes included (their mirror ghosts come from the other ranks' reflected
 * boxes); a relaxation is made per rank, each rank moving its slice of the
 * body's points. */
static int per_rank_setup(const sph_method_ops *method) {
  return sph_domain_world_size() > 1 && method->distributed;
}

/* Every term a distributed method creates must run on owned particles. */
static sph_status check_distributed_terms(const sph_sim *sim, sph_error *err) {
  for (int i = 0; sim->domain && i < sim->nterms; ++i)
    if (!sim->terms[i].ops->distributed)
      return sph_node_error(sim->scene->method, err, SPH_ERR_UNSUPPORTED,
                            "the term %s does not run over MPI ranks yet; "
                            "run without mpirun",
                            sim->terms[i].ops->name);
  return SPH_OK;
}

/* The sim's own structure, the same on every rank: the method's hooks, the
 * terms and the timers within their tables (O(terms)). */
static sph_status check_sim(const sph_sim *sim, sph_error *err) {
  const sph_method_ops *m = sim->method;
  SPH_CHECK(sim->ps && m && m->step && m->stable_dt && m->derive && m->energy &&
                m->state,
            err, "simulation without particles or a method hook");
  SPH_CHECK(sim->nterms >= 0 && sim->nterms <= SPH_MAX_TERMS, err,
            "%d terms (table of %d)", sim->nterms, SPH_MAX_TERMS);
  for (int i = 0; i < sim->nterms; ++i)
    SPH_CHECK(sim->terms[i].ops && sim->terms[i].ops->name, err,
              "term %d has no ops table", i);
  SPH_CHECK(sim->ntimers >= 0 && sim->ntimers <= SPH_MAX_TIMERS &&
                sim->timer_stable_dt >= 0 &&
                sim->timer_stable_dt < sim->ntimers,
            err, "timer %d of %d (table of %d)", sim->timer_stable_dt,
            sim->ntimers, SPH_MAX_TIMERS);
  return SPH_OK;
}

/* This rank's particle set: its count within its capacity, the arrays
 * every particle has (O(1)). */
static sph_status check_particles(const sph_particles *ps, sph_error *err) {
  SPH_CHECK(ps->n <= ps->capacity && ps->dim >= 1 && ps->dim <= 3, err,
            "%zu particles in a set of %zu (dimension %d)", ps->n, ps->capacity,
            ps->dim);
  SPH_CHECK(ps->field[SPH_FIELD_POSITION0] && ps->field[SPH_FIELD_VOLUME0] &&
                ps->id && ps->body && ps->flags,
            err, "particle set without positions, volumes or attributes");
  return SPH_OK;
}

/* SPH_DEBUG_CHECKS: the method's state arrays x, p or v and F hold finite
 * values (after a step: SPH_ERR_NUMERIC, the verdict's `nan`, which the
 * next step's time step would report at the same time), and at set-up
 * every F has det F > 0 (O(N) over the arrays; collective). */
static sph_status check_state(sph_sim *sim, int setup, sph_error *err) {
  sph_state_array arr[SPH_MAX_STATE];
  int k = sim->method->state(sim, arr);
  SPH_CHECK(k >= 0 && k <= SPH_MAX_STATE, err, "%s: %d state arrays",
            sim->method->name, k);
  for (int i = 0; i < k; ++i) {
    const char *name = arr[i].name;
    const double *v = arr[i].data;
    if (strcmp(name, "x") && strcmp(name, "p") && strcmp(name, "v") &&
        strcmp(name, "F"))
      continue;
    size_t j = 0;
    while (j < arr[i].len && isfinite(v[j]))
      ++j;
    SPH_CHECK_AS(SPH_ERR_NUMERIC, j == arr[i].len, err,
                 "%s: state %s[%zu] is %g at t = %g (step %lu)",
                 sim->method->name, name, j, j < arr[i].len ? v[j] : 0.0,
                 sim->t, sim->steps);
    for (size_t a = 0; setup && !strcmp(name, "F") && a + 9 <= arr[i].len;
         a += 9)
      SPH_CHECK(sph_mat3_det(v + a) > 0.0, err,
                "%s: det F = %g at set-up (entry %zu of F)", sim->method->name,
                sph_mat3_det(v + a), a / 9);
  }
  return SPH_OK;
}

sph_status sph_sim_check_memory(const sph_scene *scene, sph_error *err) {
  double dp = sph_scene_min_spacing(scene);
  sph_kernel kernel;
  SPH_TRY(sph_kernel_create(&kernel, scene->kernel_type, scene->dimension,
                            scene->h_over_dp * dp, err));
  return check_memory(scene, kernel.support, dp, err);
}

sph_status sph_sim_create(sph_sim **out, const sph_scene *scene,
                          sph_error *err) {
  *out = NULL;
  sph_node *name_node = sph_node_child(scene->method, "name");
  const sph_method_ops *method = sph_method_find(scene->method_name);
  if (!method)
    return sph_method_unknown(scene->method_name,
                              name_node ? name_node : scene->method, err);
  sph_sim *sim = calloc(1, sizeof *sim);
  if (!sim)
    return sph_error_set(err, SPH_ERR_NOMEM, "simulation");
  sim->scene = scene;
  sim->method = method;
  sim->threads = omp_get_max_threads();
  sim->dt_min = INFINITY;
  sim->dp = sph_scene_min_spacing(scene);
  sph_status st =
      sph_kernel_create(&sim->kernel, scene->kernel_type, scene->dimension,
                        scene->h_over_dp * sim->dp, err);
  if (st == SPH_OK)
    st = check_memory(scene, sim->kernel.support, sim->dp, err);
  /* over MPI ranks: this rank's share of the particles, in the order below */
  int64_t *gidx = NULL, first = INT64_MAX;
  size_t N = 0;
  if (st == SPH_OK && per_rank_setup(method))
    st = sph_scene_build_share(scene, sim->kernel.support,
                               sph_domain_world_rank(), sph_domain_world_size(),
                               &sim->ps, &gidx, &N, &first, err);
  /* a rank's error about its particles: the one of the lowest creation
   * index, the whole set's */
  st = sph_domain_world_first(st, first, err);
  if (st == SPH_OK && !sim->ps)
    st = sph_scene_build_particles(scene, &sim->ps, err);
  /* neighbours near in memory: cells of one kernel support in Morton order */
  if (st == SPH_OK && !gidx)
    st = sph_particles_sort_morton(sim->ps, sim->kernel.support, err);
  st = sph_domain_world_agree(st, err);
  if (st == SPH_OK)
    st = sph_reference_create(&sim->reference, scene, err);
  /* over MPI ranks: this rank's owned particles from here on */
  if (st == SPH_OK && sph_domain_world_size() > 1)
    st = distribute(sim, gidx, N, err);
  free(gidx);
  if (st == SPH_OK && sim->reference)
    st = sph_reference_initialise(sim->reference, sim, err);
  if (st == SPH_OK)
    st = method->setup(sim, scene->method, err);
  if (st == SPH_ERR_SINGULAR)
    blame_singular(sim, err);
  /* a rank whose set-up failed alone must not leave the others waiting */
  if (sim->domain)
    st = sph_domain_agree(sim->domain, st, err);
  if (st == SPH_OK && SPH_DEBUG_CHECKS_ON)
    st = sph_domain_agree(sim->domain, check_state(sim, 1, err), err);
  if (st == SPH_OK)
    st = check_distributed_terms(sim, err);
  if (st == SPH_OK)
    st = check_output_fields(sim, err);
  /* the time step rule (a wave speed per particle) is work of every step */
  if (st == SPH_OK)
    sim->timer_stable_dt = sph_sim_add_timer(sim, "stable_dt");
  if (st == SPH_OK)
    st = check_sim(sim, err);
  if (st != SPH_OK) {
    sph_node_blame_set(scene->root, scene->path, err);
    sph_sim_destroy(sim);
    return st;
  }
  *out = sim;
  return SPH_OK;
}

void sph_sim_destroy(sph_sim *sim) {
  if (!sim)
    return;
  for (int i = 0; i < sim->nterms; ++i)
    if (sim->terms[i].ops->destroy)
      sim->terms[i].ops->destroy(&sim->terms[i]);
  sph_device_run_destroy(sim->device);
  if (sim->method && sim->method->destroy)
    sim->method->destroy(sim);
  sph_particles_destroy(sim->ps);
  sph_reference_destroy(sim->reference);
  sph_domain_destroy(sim->domain);
  free(sim);
}

double sph_sim_stable_dt(sph_sim *sim) {
  double dt = sim->method->stable_dt(sim);
  for (int i = 0; i < sim->nterms; ++i)
    if (sim->terms[i].ops->stable_dt)
      dt = fmin(dt, sim->terms[i].ops->stable_dt(&sim->terms[i], sim));
  /* the smallest over the ranks (exact: the serial run's step) */
  return sph_domain_min(sim->domain, dt);
}

sph_status sph_sim_step(sph_sim *sim, double dt_cap, sph_error *err) {
  SPH_TRY(check_sim(sim, err));
  double t0 = sph_wtime();
  double dt = sph_sim_stable_dt(sim);
  sim->timers[sim->timer_stable_dt].seconds += sph_wtime() - t0;
  sim->timers[sim->timer_stable_dt].calls++;
  if (!(dt > 0.0) || !isfinite(dt))
    return sph_error_set(err, SPH_ERR_NUMERIC,
                         "stable time step %g at t = %g is not positive", dt,
                         sim->t);
  /* particles closing onto each other shrink a pair-based step without
   * bound: a run that would never end */
  if (dt < SPH_DT_COLLAPSE * sim->dt_stable_peak)
    return sph_error_set(err, SPH_ERR_RANGE,
                         "time step collapse: stable step %.3g s at t = %g "
                         "is below %g of the largest so far (%.3g s)",
                         dt, sim->t, SPH_DT_COLLAPSE, sim->dt_stable_peak);
  sim->dt_stable_peak = fmax(sim->dt_stable_peak, dt);
  if (dt > dt_cap)
    dt = dt_cap;
  /* dt_cap is the same on every rank */
  SPH_CHECK(dt > 0.0 && isfinite(dt), err,
            "time step %g at t = %g (stable %g, cap %g)", dt, sim->t,
            sim->dt_stable_peak, dt_cap);
  sph_status st = sim->device ? sph_device_run_step(sim->device, dt, err)
                              : sim->method->step(sim, dt, err);
  if (st == SPH_ERR_SINGULAR)
    blame_singular(sim, err);
  /* a rank's failed check reaches every rank through the agreement */
  if (st == SPH_OK)
    st = check_particles(sim->ps, err);
  st = sph_domain_agree(sim->domain, st, err);
  if (st != SPH_OK)
    return st;
  sim->t += dt;
  sim->steps++;
  sim->dt_last = dt;
  sim->dt_min = dt < sim->dt_min ? dt : sim->dt_min;
  sim->dt_max = dt > sim->dt_max ? dt : sim->dt_max;
  if (SPH_DEBUG_CHECKS_ON)
    return sph_domain_agree(sim->domain, check_state(sim, 0, err), err);
  return SPH_OK;
}
