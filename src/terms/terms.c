/* The terms a method composes and the method's named timers (docs/design.md
 * sec. 4): methods add them in setup; each rates / constrain hook is run in
 * order and timed for summary.json's terms; the list of every term's ops
 * table (term_list.h). */
#include "solver/sim.h"
#include "terms/terms_impl.h"

#include <string.h>

sph_status sph_sim_add_term(sph_sim *sim, const sph_term_ops *ops, void *data,
                            sph_error *err) {
  if (sim->nterms >= SPH_MAX_TERMS)
    return sph_error_set(err, SPH_ERR_ARG, "more than %d terms", SPH_MAX_TERMS);
  sph_term *t = &sim->terms[sim->nterms++];
  memset(t, 0, sizeof *t);
  t->ops = ops;
  t->data = data;
  return SPH_OK;
}

int sph_sim_add_timer(sph_sim *sim, const char *name) {
  if (sim->ntimers >= SPH_MAX_TIMERS)
    return SPH_MAX_TIMERS - 1;
  sim->timers[sim->ntimers].name = name;
  return sim->ntimers++;
}

sph_status sph_sim_terms_rates(sph_sim *sim, sph_stage *stage, sph_error *err) {
  for (int i = 0; i < sim->nterms; ++i) {
    sph_term *t = &sim->terms[i];
    if (!t->ops->rates)
      continue;
    double t0 = sph_wtime();
    sph_status st = t->ops->rates(t, sim, stage, err);
    t->seconds += sph_wtime() - t0;
    t->calls++;
    if (st != SPH_OK)
      return st;
  }
  return SPH_OK;
}

sph_status sph_sim_terms_constrain(sph_sim *sim, sph_stage *state,
                                   sph_error *err) {
  for (int i = 0; i < sim->nterms; ++i) {
    sph_term *t = &sim->terms[i];
    if (!t->ops->constrain)
      continue;
    double t0 = sph_wtime();
    sph_status st = t->ops->constrain(t, sim, state, err);
    t->seconds += sph_wtime() - t0;
    t->calls++;
    if (st != SPH_OK)
      return st;
  }
  return SPH_OK;
}

sph_status sph_sim_terms_renumber(sph_sim *sim, sph_error *err) {
  for (int i = 0; i < sim->nterms; ++i)
    if (sim->terms[i].ops->renumber)
      SPH_TRY(sim->terms[i].ops->renumber(&sim->terms[i], sim, err));
  return SPH_OK;
}

#define SPH_TERM_ENTRY(id) &id##_term_ops,
static const sph_term_ops *const terms[] = {
    SPH_TERM_LIST(SPH_TERM_ENTRY) SPH_TERM_LIST_EXTRA(SPH_TERM_ENTRY) NULL};
#undef SPH_TERM_ENTRY

const sph_term_ops *const *sph_term_list(void) { return terms; }
