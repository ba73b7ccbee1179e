/* The sink registry: every output sink once, in the order the run opens
 * them and hands them each frame (energy.csv, the .vtp series, probes.csv,
 * the PNG frames). X(name) names the ops table sph_<name>_sink_ops. A new
 * sink is one entry here plus its file; SPH_SINK_LIST_EXTRA(X) appends
 * sinks defined outside the tree (a test's toy sink). */
#ifndef SPH_SINK_LIST_H
#define SPH_SINK_LIST_H

#ifndef SPH_SINK_LIST_EXTRA
#define SPH_SINK_LIST_EXTRA(X)
#endif

#define SPH_SINK_LIST(X) X(energy) X(vtk) X(probe) X(png) SPH_SINK_LIST_EXTRA(X)

#endif
