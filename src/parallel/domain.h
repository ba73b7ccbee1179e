/* Distributed runs: the one place that calls MPI (issue 20). Particles are
 * partitioned by recursive coordinate bisection of their reference
 * positions, balanced by count; a rank keeps its owned particles and, for
 * the total-Lagrangian methods, the ghosts: every particle within one
 * kernel support of an owned one in the reference configuration. The
 * ghost set and the exchange pattern are fixed at set-up.
 *
 * Without MPI (built with SPH_MPI=OFF, or started without a launcher) the
 * process is rank 0 of 1, sph_sim.domain is NULL and every call below taking
 * a domain is a no-op that returns its input: the serial path is unchanged. */
#ifndef SPH_DOMAIN_H
#define SPH_DOMAIN_H

#include <stddef.h>
#include <stdint.h>

#include "core/neighbors.h"
#include "core/particles.h"
#include "parallel/planes.h"
#include "sph/status.h"

typedef struct sph_domain sph_domain;

/* Starts MPI when the process was started by a launcher (mpirun); returns
 * SPH_ERR_UNSUPPORTED when it was but the build has no MPI. */
sph_status sph_domain_init(int *argc, char ***argv, sph_error *err);
void sph_domain_finalize(void);
/* This process's rank and the rank count (0 and 1 without MPI). */
int sph_domain_world_rank(void);
int sph_domain_world_size(void);

/* Partitions *ps (every particle, the same on every rank, in storage
 * order) over the ranks (the whole-set twin the per-rank set-up below is
 * tested against; runs use sph_domain_create_share): *ps becomes this rank's
 * owned particles in the same relative order (no rank keeps the whole set).
 * Ghosts are the particles of the same body within `support` of an owned one
 * (strictly, as sph_neighbors_build). Refuses a rank count for which a rank
 * would hold more ghosts than owned particles. */
sph_status sph_domain_create(sph_domain **out, sph_particles **ps,
                             double support, sph_error *err);
void sph_domain_destroy(sph_domain *d);
/* sph_domain_create without the whole set: each rank passes its share of
 * the N particles (*ps, any subset as sph_scene_build_share makes them,
 * with their storage indices gidx; *ps becomes the owned set, NULL after
 * an error past the partition); the owned sets, storage indices,
 * ghosts and halo are sph_domain_create's; with dynamic, the owned sets
 * and cut tree of sph_domain_create_dynamic. Collective. */
sph_status sph_domain_create_share(sph_domain **out, sph_particles **ps,
                                   const int64_t *gidx, size_t N,
                                   double support, int dynamic, sph_error *err);
/* sph_domain_agree over every rank before a domain exists (st for one
 * rank). */
sph_status sph_domain_world_agree(sph_status st, sph_error *err);
/* The same, the error of the failing rank with the lowest key (then the
 * lowest rank). */
sph_status sph_domain_world_first(sph_status st, int64_t key, sph_error *err);
/* The ranks on this rank's node (sharing its memory; 1 without MPI). */
int sph_domain_node_size(void);
/* The same, counted once by sph_domain_init (no communication). */
int sph_domain_node_ranks(void);
/* Before MPI starts: sets OMPI_MCA_mpi_yield_when_idle=1 unless it is set
 * (waiting ranks yield the core); 1 when it set it. */
int sph_domain_idle_defaults(void);

/* sph_domain_create for a run with mirror images: the ghosts are also the
 * particles within two supports of the owned ones or of their reflections
 * (chained over the planes, each within four supports of its plane), so a
 * rank holds the sources of every image within one support of an owned
 * particle and the whole neighbourhood of each such image. */
sph_status sph_domain_create_mirrored(sph_domain **out, sph_particles **ps,
                                      double support,
                                      const sph_domain_plane *planes,
                                      int nplanes, sph_error *err);
/* sph_domain_create_mirrored from each rank's share (as
 * sph_domain_create_share): the same owned sets, ghosts (in their order)
 * and halo, with each rank's reflected boxes exchanged instead of a search
 * over the whole set. Collective. */
sph_status sph_domain_create_share_mirrored(sph_domain **out,
                                            sph_particles **ps,
                                            const int64_t *gidx, size_t N,
                                            double support,
                                            const sph_domain_plane *planes,
                                            int nplanes, sph_error *err);
/* Storage indices in the whole set of the owned particles, then of the
 * ghosts (NULL for NULL). */
const int64_t *sph_domain_storage_index(const sph_domain *d);
/* Exchanges write the ghosts' values from point `base` on (default: right
 * after the owned particles), for a method that keeps other points (mirror
 * images) in between. */
void sph_domain_set_ghost_base(sph_domain *d, size_t base);

int sph_domain_rank(const sph_domain *d);
int sph_domain_size(const sph_domain *d);

/* The ghosts (0 for NULL), their reference positions (3 per ghost),
 * volumes, bodies and particle ids, grouped by owner. */
size_t sph_domain_ghosts(const sph_domain *d);
const double *sph_domain_ghost_X(const sph_domain *d);
const double *sph_domain_ghost_volume(const sph_domain *d);
const int32_t *sph_domain_ghost_body(const sph_domain *d);
const int64_t *sph_domain_ghost_id(const sph_domain *d);
/* The halo over all ranks (collective): values sent per exchange of one
 * double per ghost (the ghosts of every rank), messages per exchange, and
 * the most ghosts and owned particles of a rank. */
typedef struct sph_halo {
  double values, messages, max_ghosts, max_owned;
} sph_halo;
sph_halo sph_domain_halo(sph_domain *d);

/* Sorts each of the first n lists of nl, built over the owned particles
 * followed by the ghosts, by the particles' storage index in the whole set:
 * pair sums then run in the order of the serial run. */
void sph_domain_sort_lists(const sph_domain *d, sph_neighbors *nl, size_t n);
/* The same by key[point] (ascending) for every point of the lists. */
void sph_domain_sort_lists_by(sph_neighbors *nl, size_t n, const int64_t *key);

/* Sets the ghosts' ncomp values, field + ncomp * n_owned onwards, from
 * their owners' (non-blocking point to point). */
sph_status sph_domain_exchange(sph_domain *d, double *field, int ncomp,
                               sph_error *err);

/* Global minimum and maximum; sums of count values added in rank order
 * (the same bits for a fixed rank count). */
double sph_domain_min(sph_domain *d, double v);
double sph_domain_max(sph_domain *d, double v);
/* lo[i] becomes the least and hi[i] the greatest over the ranks, i < n
 * (collective, exact; one reduction for 16 pairs). */
void sph_domain_minmax(sph_domain *d, double *lo, double *hi, int n);
void sph_domain_sum(sph_domain *d, double *v, int count);
/* The same for any count, chunk values at a time through work (the rank
 * count times chunk doubles). */
void sph_domain_sum_long(sph_domain *d, double *v, size_t count, double *work,
                         size_t chunk);
/* Root's value on every rank. */
int sph_domain_bcast_int(sph_domain *d, int v);
/* Every rank receives every rank's count values in rank order: *out
 * (allocated, to be freed) holds *total of them, this rank's from *first
 * (when not NULL). Outside the time step only (it allocates). */
sph_status sph_domain_allgather_i64(sph_domain *d, const int64_t *v,
                                    size_t count, int64_t **out, size_t *total,
                                    size_t *first, sph_error *err);
/* Rank 0 receives count values of every rank in rank order (out: count
 * per rank; unused on the other ranks). */
void sph_domain_gather_u64(sph_domain *d, const uint64_t *v, int count,
                           uint64_t *out);

/* Every rank learns whether any failed: the error of the lowest failing
 * rank is returned on all (st itself for NULL). */
sph_status sph_domain_agree(sph_domain *d, sph_status st, sph_error *err);

/* Wall seconds this rank spent in halo exchanges, reductions and gathers
 * (waiting for the other ranks included). */
double sph_domain_seconds(const sph_domain *d);
/* The doubles and messages this rank's halo exchanges have sent so far
 * (0 for NULL). */
void sph_domain_traffic(const sph_domain *d, double *values, double *messages);

/* Whether particles migrate between ranks (an updated-Lagrangian run; 0
 * for NULL): a checkpoint piece then holds its rank's owned particles and
 * domain state (sph_domain_checkpoint). */
int sph_domain_migrates(const sph_domain *d);

/* The particles of the whole run: over all ranks, ps->n for NULL. */
size_t sph_domain_particles(const sph_domain *d, const sph_particles *ps);
/* The other ranks' points (ncomp doubles each, the first 3 the position)
 * within `radius` of this rank's box of its n points pts, received into
 * *out (grown to *cap doubles when short) by rank, *m of them
 * (collective; *m = 0 for NULL). */
sph_status sph_domain_box_points(sph_domain *d, const double *pts, size_t n,
                                 int ncomp, double radius, double **out,
                                 size_t *cap, size_t *m, sph_error *err);
/* The ncomp values of the particles with the storage indices want[0 ..
 * nwant) into out, answered by their owners (collective: every rank's
 * requests are gathered; each passes its n owned particles' storage
 * indices key in ascending order and their values val); 0 for an index
 * no rank owns. */
sph_status sph_domain_fetch(sph_domain *d, const int64_t *want, size_t nwant,
                            const int64_t *key, const double *val, size_t n,
                            int ncomp, double *out, sph_error *err);
/* Rank 0 receives into out, for each of m rows of w doubles, the row of
 * the lowest rank whose row k starts with a non-zero flag (flag included;
 * rows of no rank are left; collective; nothing for NULL). */
sph_status sph_domain_pick(sph_domain *d, const double *rows, size_t m, int w,
                           double *out, sph_error *err);
/* Rank 0 receives into out the w doubles of each particle whose storage
 * index k is in [lo, lo + m), at out + w * (k - lo), from its owner: each
 * rank passes the n rows of its particles in that range and their storage
 * indices key (collective; out is filled directly for NULL). Outside the
 * time step only (it allocates). */
sph_status sph_domain_gather_range(sph_domain *d, const int64_t *key,
                                   const double *rows, size_t n, int w,
                                   int64_t lo, size_t m, double *out,
                                   sph_error *err);

/* ---- updated-Lagrangian runs (src/parallel/domain_dynamic.c) ----------
 * Their neighbourhoods change, so a dynamic domain is partitioned like the
 * fixed one but finds its ghosts at every rebuild of the method's
 * neighbour lists: particles that left the rank's RCB region move to their
 * owner (migration), the ranks are cut again by RCB of the current
 * positions when the most loaded owns more than SPH_DOMAIN_IMBALANCE over
 * the mean (re-balance), and the ghosts are the other ranks' particles in
 * the rank's box of owned particles widened by the search radius. Every
 * per-particle array of the local set is sized at set-up for
 * sph_domain_capacity particles (owned + ghosts); a rank that would
 * outgrow it fails with SPH_ERR_RANGE, nothing grows in a step. */
#define SPH_DOMAIN_IMBALANCE 0.10

sph_status sph_domain_create_dynamic(sph_domain **out, sph_particles **ps,
                                     double support, sph_error *err);
/* Particles every per-particle array must hold (ps->n without a domain). */
size_t sph_domain_capacity(const sph_domain *d, const sph_particles *ps);
/* A method's own per-particle array (ncomp doubles a particle, capacity
 * long) that moves with its particle and is copied to ghosts; the fields
 * of the particle set, its ids, bodies and flags always do. */
sph_status sph_domain_track(sph_domain *d, double *array, int ncomp,
                            sph_error *err);
/* The rebuild (collective): migration, re-balance when due, ghosts of the
 * positions field within `radius`. On return ps->n is the owned count and
 * the ghosts' values follow it in every field and tracked array. */
sph_status sph_domain_rebuild(sph_domain *d, sph_particles *ps, double radius,
                              sph_error *err);
/* Symmetry planes of a dynamic domain's run (nothing for NULL or a fixed
 * domain): its rebuilds take as ghosts the other ranks' particles within
 * `depth` radii of the box of a rank's owned particles or of the box's
 * reflections (chained over the planes, each within depth + 2 radii of its
 * plane, where the images' sources lie), so a rank holds the sources of
 * the images near its particles and their neighbourhoods. */
sph_status sph_domain_dyn_mirror(sph_domain *d, const sph_domain_plane *planes,
                                 int np, double depth, sph_error *err);
/* Every rank's owned particles' w values (mine, w a particle) into all (w
 * per particle of the whole set, by storage index); collective, set-up use
 * (it allocates). Nothing for NULL or a fixed domain. */
sph_status sph_domain_allgather(sph_domain *d, const double *mine, int w,
                                double *all, sph_error *err);
/* Sets the ghosts' values of `count` arrays (ncomp[i] doubles a particle,
 * at most 32 doubles in all) in one message per neighbour rank. */
sph_status sph_domain_exchange_many(sph_domain *d, double *const *fields,
                                    const int *ncomp, int count,
                                    sph_error *err);
/* Checkpoints of a dynamic domain (returns 0 for a fixed one or NULL, else
 * 1): in buffers the domain holds, the first n owned particles packed with
 * every field, id, body, flags, storage index and tracked array
 * (*particles, *np doubles) and the domain's own state: the cut tree, the
 * counters of sph_domain_moves_of and the halo plan of the last rebuild
 * (*state, *ns doubles). With fill they are packed from ps (between
 * steps, for writing), else they are the room a piece's arrays are read
 * into (n at most sph_domain_capacity), then put in place by
 * sph_domain_resume. */
int sph_domain_checkpoint(sph_domain *d, const sph_particles *ps, size_t n,
                          int fill, double **particles, size_t *np,
                          double **state, size_t *ns);
/* After a piece's arrays were read into those buffers: its n owned
 * particles in their order and the domain's state in place (ps->n = n), so
 * the partition is the checkpoint's, not a new RCB; the next
 * sph_domain_rebuild (the method's restore) then sends the ghosts of the
 * checkpoint's halo plan instead of migrating. SPH_ERR_IO when the state
 * does not fit this run. */
sph_status sph_domain_resume(sph_domain *d, sph_particles *ps, size_t n,
                             sph_error *err);
/* Over the run and all ranks: particles migrated, re-balances, rebuilds,
 * the largest halo (particles sent per exchange, all ranks) and the most
 * ghosts a rank held (zeros for a fixed domain). */
typedef struct sph_domain_moves {
  double migrated, rebalances, rebuilds, halo_max, ghosts_max;
} sph_domain_moves;
sph_domain_moves sph_domain_moves_of(const sph_domain *d);

#endif
