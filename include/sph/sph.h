/* The sph library's public C API in one header, for programs that embed
 * the solver (examples/embed.c; pkg-config --cflags --libs sph):
 *
 *   sph_scene_load    a YAML scene file, with key=value overrides
 *   sph_sim_create    particles, the method and its terms from the scene
 *   sph_sim_step      one step of at most dt_cap
 *   sim->method->derive / ->energy, sim->ps->field[SPH_FIELD_...]
 *                     the output fields and energies of the current state
 *   sph_sink_ops      open / write / flush / close / destroy: a sink of
 *                     one's own, or sph_vtk_sink_ops, sph_energy_sink_ops
 *   sph_verdict_*     the stability verdict `sph run` gives
 *   sph_sim_destroy, sph_scene_destroy
 *
 * Every call returns an sph_status and fills an sph_error (file, line,
 * column, key, message; sph_error_format). */
#ifndef SPH_SPH_H
#define SPH_SPH_H

#include "core/particles.h"
#include "io/sink.h"
#include "scene/scene.h"
#include "solver/sim.h"
#include "solver/stability.h"
#include "sph/status.h"

#endif
