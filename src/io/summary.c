/* summary.json: what ran, how long each part took, conservation and the
 * stability verdict (keys listed in the README). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "solver/reference.h"
#include "solver/stability.h"

static void json_string(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; ++s) {
    unsigned char c = (unsigned char)*s;
    if (c == '"' || c == '\\')
      fprintf(f, "\\%c", c);
    else if (c < 0x20)
      fprintf(f, "\\u%04x", c);
    else
      fputc(c, f);
  }
  fputc('"', f);
}

static void json_number(FILE *f, double x) {
  if (isfinite(x))
    fprintf(f, "%.17g", x);
  else
    fputs("null", f);
}

/* the program, the scene and the method that ran */
static void write_provenance(FILE *f, const sph_sim *sim,
                             const sph_provenance *prov) {
  fputs("{\n  \"sph\": {\"version\": ", f);
  json_string(f, prov->version);
  fputs(", \"commit\": ", f);
  json_string(f, prov->commit);
  fputs(", \"command\": ", f);
  json_string(f, prov->command);
  fputs("},\n  \"scene\": ", f);
  json_string(f, sim->scene->name);
  fputs(",\n  \"method\": {\"name\": ", f);
  json_string(f, sim->method->name);
  fputs(", \"title\": ", f);
  json_string(f, sim->method->title);
  fputs(", \"reference\": ", f);
  json_string(f, sim->method->reference);
}

/* each part's seconds and calls, each sink's seconds and its thread's */
static void write_timers(FILE *f, const sph_sim *sim, const sph_sink *sinks,
                         int nsinks, double mp4_seconds) {
  fputs("},\n  \"terms\": {", f);
  int first = 1;
  for (int i = 0; i < sim->ntimers; ++i) {
    fputs(first ? "" : ", ", f);
    first = 0;
    json_string(f, sim->timers[i].name);
    fputs(": ", f);
    json_number(f, sim->timers[i].seconds);
  }
  for (int i = 0; i < sim->nterms; ++i) {
    fputs(first ? "" : ", ", f);
    first = 0;
    json_string(f, sim->terms[i].ops->name);
    fputs(": ", f);
    json_number(f, sim->terms[i].seconds);
  }
  /* how often each part ran (ul-sph: configuration updates are its
   * advection steps) */
  fputs("},\n  \"calls\": {", f);
  for (int i = 0; i < sim->ntimers; ++i) {
    fputs(i ? ", " : "", f);
    json_string(f, sim->timers[i].name);
    fprintf(f, ": %lu", sim->timers[i].calls);
  }
  fputs("},\n  \"sinks\": {", f);
  for (int i = 0; i < nsinks; ++i) {
    fputs(i ? ", " : "", f);
    json_string(f, sinks[i].ops->name);
    fputs(": ", f);
    json_number(f, sinks[i].seconds);
  }
  if (mp4_seconds >= 0.0) {
    fputs(nsinks ? ", " : "", f);
    json_string(f, "mp4");
    fputs(": ", f);
    json_number(f, mp4_seconds);
  }
  /* the sinks' own threads (png: rendering), in parallel with the run */
  double thread_seconds = 0.0;
  for (int i = 0; i < nsinks; ++i)
    thread_seconds += sinks[i].thread_seconds;
  fputs("},\n  \"render_thread_seconds\": ", f);
  json_number(f, thread_seconds);
}

/* the run's size: particles, steps, ranks, the halo's moves, time steps */
static void write_run_size(FILE *f, const sph_sim *sim, double wall_seconds) {
  fprintf(f, ",\n  \"particles\": %zu,\n  \"steps\": %lu,\n",
          sph_domain_particles(sim->domain, sim->ps), sim->steps);
  if (sim->domain) /* a run over MPI ranks; the timers are rank 0's */
    fprintf(f, "  \"ranks\": %d,\n", sph_domain_size(sim->domain));
  sph_domain_moves mv = sph_domain_moves_of(sim->domain);
  if (mv.rebuilds > 0.0) /* updated Lagrangian: over the run, all ranks */
    fprintf(f,
            "  \"halo_rebuilds\": %.0f,\n  \"migrated\": %.0f,\n"
            "  \"rebalances\": %.0f,\n  \"ghosts_max\": %.0f,\n"
            "  \"halo_max\": %.0f,\n",
            mv.rebuilds, mv.migrated, mv.rebalances, mv.ghosts_max,
            mv.halo_max);
  fputs("  \"wall_seconds\": ", f);
  json_number(f, wall_seconds);
  fputs(",\n  \"dt_min\": ", f);
  json_number(f, sim->steps ? sim->dt_min : NAN);
  fputs(",\n  \"dt_max\": ", f);
  json_number(f, sim->steps ? sim->dt_max : NAN);
}

/* energy, momentum drifts, J, checkerboard, fracture and zigzag */
static void write_conservation(FILE *f, const sph_verdict *v) {
  fputs(",\n  \"energy\": {\"initial\": ", f);
  json_number(f, v->energy0);
  fputs(", \"final\": ", f);
  json_number(f, v->energy_final);
  fputs(", \"max\": ", f);
  json_number(f, v->energy_max);
  fputs("},\n  \"linear_momentum_drift\": ", f);
  json_number(f, v->lin_drift);
  fputs(",\n  \"angular_momentum_drift\": ", f);
  json_number(f, v->ang_drift);
  fputs(",\n  \"J\": {\"min\": ", f);
  json_number(f, v->J_min);
  fputs(", \"max\": ", f);
  json_number(f, v->J_max);
  fputs("},\n  \"checkerboard_max\": ", f);
  json_number(f, v->checkerboard_max);
  fputs(",\n  \"fracture\": {\"max_stretch_dp\": ", f);
  json_number(f, v->npairs ? v->fracture_peak_stretch : NAN);
  fprintf(f,
          ", \"pairs_over\": %ld},\n  \"zigzag_max\": ", v->fracture_peak_over);
  json_number(f, v->zigzag_max);
  /* particles R is judged on (0: every body too coarse to judge) */
  fprintf(f, ",\n  \"zigzag_judged_particles\": %zu", v->zigzag_count);
}

/* the verdict and when each indicator tripped */
static void write_verdict(FILE *f, const sph_verdict *v) {
  fprintf(f, ",\n  \"nan\": %s,\n  \"stable\": %s,\n  \"reason\": ",
          v->nan ? "true" : "false", v->stable ? "true" : "false");
  json_string(f, v->reason);
  fputs(",\n  \"tripped_at\": ", f);
  json_number(f, v->stable ? NAN : v->t_tripped);
  fputs(",\n  \"first_indicator\": ", f);
  if (v->stable)
    fputs("null", f);
  else
    json_string(f, sph_indicator_key(v->first));
  /* every indicator's trip time, null when it did not trip */
  fputs(",\n  \"indicators\": {", f);
  for (int i = 0; i < SPH_INDICATOR_COUNT; ++i) {
    fputs(i ? ", " : "", f);
    json_string(f, sph_indicator_key((sph_indicator)i));
    fputs(": ", f);
    json_number(f, v->tripped_at[i]);
  }
  fputc('}', f);
}

/* the errors against the scene's reference solution */
static void write_reference_error(FILE *f, const sph_reference_error *ref) {
  sph_reference_error e = *ref;
  /* the quantities this reference gives */
  const struct {
    const char *key;
    double x;
  } q[] = {{"l2_velocity", e.l2_velocity},
           {"l2_stress", e.l2_stress},
           {"l2_displacement", e.l2_displacement},
           {"h1_displacement", e.h1_displacement},
           {"period", e.period},
           {"period_reference", e.period_value},
           {"period_error", e.period_error},
           {"period_tolerance", e.period_tolerance}};
  const char *sep = ",\n  \"error\": {";
  size_t k0 = e.period_value > 0.0 ? 4 : 0, k1 = k0 ? 8 : 4;
  for (size_t k = k0; k < k1; ++k) {
    if (k == 7 && isnan(q[k].x)) /* no tolerance given */
      continue;
    fprintf(f, "%s\"%s\": ", sep, q[k].key);
    json_number(f, q[k].x);
    sep = ", ";
  }
  /* the paper's norms beside the nodal ones (reference norm: gauss) */
  if (!isnan(e.l2_displacement_gauss)) {
    fputs(", \"l2_displacement_gauss\": ", f);
    json_number(f, e.l2_displacement_gauss);
    fputs(", \"h1_displacement_gauss\": ", f);
    json_number(f, e.h1_displacement_gauss);
  }
  fputs("}", f);
}

/* how far the run went and what stopped it */
static void write_end(FILE *f, const sph_sim *sim, int completed,
                      const char *stopped_by) {
  fprintf(f, ",\n  \"threads\": %d,\n  \"t_end\": ", sim->threads);
  json_number(f, sim->scene->t_end);
  fputs(",\n  \"t_reached\": ", f);
  json_number(f, sim->t);
  fprintf(f, ",\n  \"completed\": %s", completed ? "true" : "false");
  fputs(",\n  \"stopped_by\": ", f);
  if (stopped_by)
    fprintf(f, "\"%s\"", stopped_by);
  else
    fputs("null", f);
  fputs("\n}\n", f);
}

sph_status sph_summary_write(const char *path, const sph_sim *sim,
                             const sph_provenance *prov, const sph_verdict *v,
                             const sph_reference_error *ref,
                             double wall_seconds, const sph_sink *sinks,
                             int nsinks, double mp4_seconds, int completed,
                             const char *stopped_by, sph_error *err) {
  sph_atomic_file af;
  sph_status st = sph_atomic_open(&af, path, err);
  if (st != SPH_OK)
    return st;
  FILE *f = af.f;
  write_provenance(f, sim, prov);
  write_timers(f, sim, sinks, nsinks, mp4_seconds);
  write_run_size(f, sim, wall_seconds);
  write_conservation(f, v);
  write_verdict(f, v);
  if (ref)
    write_reference_error(f, ref);
  write_end(f, sim, completed, stopped_by);
  st = sph_atomic_commit(&af, err);
  if (st != SPH_OK)
    sph_atomic_abort(&af);
  return st;
}
