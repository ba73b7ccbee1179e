/* The stability verdict of a run: indicators checked at every output time,
 * the first one that trips and when. Thresholds:
 *  - nan: any non-finite position, velocity or stress;
 *  - J <= 0 anywhere (inverted material);
 *  - energy growth: kinetic + strain energy above (1 + SPH_ENERGY_GROWTH_MAX)
 *    times its initial value (only for scenes without prescribed velocities
 *    or body forces, whose external work is not tracked);
 *    the kinetic energy alone above the same bound of the initial total;
 *    growth below SPH_ENERGY_FLOOR sum m c0^2 (c0 the p-wave speed; the
 *    energy of a uniform strain of about 1e-10, 1e12 times the round-off
 *    energy of double-precision states) is never judged, so a body at rest
 *    does not trip on round-off;
 *  - pressure checkerboard: the red-black mode fraction of docs/benchmarks.md
 *    D.3, C = |sum V s (p - pbar)| / sqrt(sum V * sum V (p - pbar)^2) with
 *    s_a = (-1)^(i+j+k) the parity of the particle's lattice index (bodies
 *    made from a lattice, jittered or not; relaxed bodies carry no parity).
 *    0 <= C <= 1: about 0 for smooth fields, 1 for a pure red-black
 *    alternation; tripped above SPH_CHECKERBOARD_MAX;
 *  - numerical fracture (seed 002 sec. 6.1, 6.3; docs/benchmarks.md E.5): the
 *    pairs of particles of one body that are initially adjacent (reference
 *    distance <= SPH_FRACTURE_ADJACENT dp, dp the body's spacing) are listed
 *    once; at every frame the largest current distance of a listed pair, in
 *    units of dp, is the stretch, and the run trips when a pair is more than
 *    SPH_FRACTURE_DP dp apart (OG passes 2 dp at t = 0.0011 on the rings,
 *    ENOG stays within 1.26 dp). A uniform stretch lambda moves the
 *    diagonal neighbours (sqrt(2) dp) to sqrt(2) lambda dp, so scenes with
 *    physical stretches beyond about 1.4 raise `stability: {fracture_dp}`;
 *  - zig-zag (hourglass) pattern of the von Mises stress s (seed 002 Fig. 1c,
 *    9): R = sqrt(sum V (s - s~)^2) / sqrt(sum V (s - sbar)^2), s~_a the
 *    value at x_a of the kernel-weighted linear least-squares fit of s over
 *    a's neighbours of the same body in the current configuration
 *    (Wendland C2, h = 1.3 dp, a itself excluded; the plain kernel average
 *    where the neighbours lie on a line or a plane) and sbar the
 *    volume-weighted mean; NaN when the field is uniform (spread below
 *    SPH_ZIGZAG_FLOOR times the largest shear modulus). The fit reproduces
 *    linear fields exactly, at a boundary too, so R measures what a smooth
 *    field cannot explain. Measured in tests/unit/test_verdict.c on
 *    lattices jittered by 0.25 dp (2D 20 x 20, 3D 10 x 10 x 10): linear /
 *    quadratic fields 0 (round-off) / 0.010 (2D), 0 / 0.029 (3D); the same
 *    plus an alternation +-0.2 (max - min) 1.05 / 0.97 (2D), 0.95 / 0.90
 *    (3D); +-0.1: 0.64 / 0.57, 0.60 / 0.55; a pure alternation 1.58 (2D),
 *    1.36 (3D) (3D measured on 10^3 before the coarse-body rule; 12^3 now:
 *    0 / 0.021, 0.94 / 0.88). Tripped above SPH_ZIGZAG_MAX = 0.5: 17 times the
 * roughest smooth field, 1.8 times below the mildest 20 % alternation, i.e.
 *    alternations of more than about 10 % of the field's range. A body
 *    is judged only when its interior (particles with no surface particle,
 *    one whose support holds fewer than SPH_ZIGZAG_SURFACE of a full
 *    support's particles, in their support) holds at least one support's
 *    worth of particles: coarser bodies resolve the field by 1-3 particles
 *    between surfaces and measure 0.5-1.2 on smooth fields (5-across
 *    columns, the 6^3 spinning cube 0.96, the 8^3 tensile cube 0.68, the
 *    3-layer 3D plate 1.0); their R is NaN. The inertial punch (11^3)
 *    is judged and its stress concentration measures 1.18: that scene
 *    switches the indicator off. ul-sph on the B4 plate to 0.1 s: ENOG
 *    0.10, OG 0.66 at 0.025 s (seed 002 Fig. 1c).
 * Both work from positions, reference positions, body ids and von Mises
 * only, so they apply to every method; their lists are allocated at
 * creation (the current-configuration lists grow only when an output
 * frame needs more room) and cost O(N) per frame.
 * Over MPI ranks every rank judges its owned particles: the minima, maxima,
 * counts and sums (in rank order) are reduced over the ranks; the zig-zag
 * fit and the surface flags read the other ranks' particles within the
 * zig-zag radius (two at creation) of the rank's box, exchanged at every
 * frame, its neighbour lists sorted by storage index so each fit is the
 * serial one bit for bit; a pair of the fracture list is judged by the rank
 * that owned its first particle (by storage index) at creation, a partner
 * beyond those points fetched from its owner by storage index. */
#ifndef SPH_STABILITY_H
#define SPH_STABILITY_H

#include "core/neighbors.h"
#include "io/sink.h"
#include "solver/reference.h"

/* The indicators, in the order a frame checks them: enum name, the key in
 * summary.json and `sph run`'s verdict line. `step` is a time step that
 * failed for a reason other than a non-finite value. */
#define SPH_INDICATOR_LIST(X)                                                  \
  X(SPH_INDICATOR_NAN, "nan")                                                  \
  X(SPH_INDICATOR_JACOBIAN, "jacobian")                                        \
  X(SPH_INDICATOR_ENERGY_GROWTH, "energy_growth")                              \
  X(SPH_INDICATOR_CHECKERBOARD, "checkerboard")                                \
  X(SPH_INDICATOR_FRACTURE, "fracture")                                        \
  X(SPH_INDICATOR_ZIGZAG, "zigzag")                                            \
  X(SPH_INDICATOR_STEP, "step")

typedef enum sph_indicator {
#define SPH_INDICATOR_ENUM(id, key) id,
  SPH_INDICATOR_LIST(SPH_INDICATOR_ENUM)
#undef SPH_INDICATOR_ENUM
      SPH_INDICATOR_COUNT,
  SPH_INDICATOR_NONE = -1
} sph_indicator;

/* The key of an indicator ("none" for SPH_INDICATOR_NONE). */
const char *sph_indicator_key(sph_indicator i);

#define SPH_ENERGY_GROWTH_MAX 0.05
#define SPH_ENERGY_FLOOR 1e-20
#define SPH_REST_START 1e-12
#define SPH_CHECKERBOARD_MAX 0.5
#define SPH_FRACTURE_ADJACENT 1.5
#define SPH_FRACTURE_DP 2.0
#define SPH_ZIGZAG_H_OVER_DP 1.3
#define SPH_ZIGZAG_FLOOR 1e-8
#define SPH_ZIGZAG_MAX 0.5
#define SPH_ZIGZAG_CONDITION 1e-3
#define SPH_ZIGZAG_SURFACE 0.75

typedef struct sph_verdict {
  int stable;
  int nan;
  char reason[256];
  double t_tripped;
  /* the first indicator that tripped and the time each one tripped (NaN:
   * never); several can trip at the frame that ends the run */
  sph_indicator first;
  double tripped_at[SPH_INDICATOR_COUNT];
  int energy_tracked;
  int frames;
  double energy0, energy_max, energy_final;
  double energy_floor; /* SPH_ENERGY_FLOOR sum m c0^2 */
  double J_min, J_max;
  double checkerboard, checkerboard_max;
  double lin0[3], ang0[3], lin_scale, ang_scale;
  double lin_drift, ang_drift; /* largest relative drift seen */
  signed char *parity;         /* s_a = +-1, 0 without a lattice */
  size_t parity_cap;
  int has_parity;
  /* numerical fracture: threshold in dp (0 = not judged), adjacent pairs */
  double fracture_dp;
  size_t npairs;                /* over all ranks */
  size_t npairs_local;          /* the pairs this rank judges */
  int64_t *pairs;               /* 2 * npairs_local storage indices */
  double fracture_max_stretch;  /* this frame: max |x_a - x_b| / dp */
  long fracture_pairs_over;     /* this frame: pairs beyond fracture_dp */
  double fracture_peak_stretch; /* largest over the frames */
  long fracture_peak_over;
  /* zig-zag: threshold (0 = not judged), R of the latest frame (NaN when
   * not measured) and the largest */
  double zigzag_threshold;
  double zigzag, zigzag_max;
  double stress_floor; /* SPH_ZIGZAG_FLOOR * the largest shear modulus */
  size_t n;            /* particles the lists were made for */
  size_t nbodies;
  double *body_dp;         /* spacing of every body */
  sph_kernel *body_kernel; /* Wendland C2 with h = 1.3 dp of every body */
  double zigzag_radius;    /* largest support */
  /* bodies R is judged on: those with an interior at least one support
   * across (none when every body is too coarse), and their particles */
  char *body_judged;
  size_t zigzag_count;
  sph_neighbors *nl; /* current-configuration lists, reused */
  double *work;      /* n entries */
  size_t work_cap;
  /* over MPI ranks (NULL serially): each rank judges its owned particles
   * with the other ranks' particles within the zig-zag radius of its box
   * (points: position, von Mises, body, storage index), the indicators
   * are reduced over the ranks */
  sph_domain *dom;
  double *pts, *near; /* owned packed, received */
  size_t pts_cap, near_cap, nnear;
  double *lx, *ls; /* owned then received: positions, von Mises */
  int32_t *lbody;
  int64_t *lkey; /* storage indices */
  size_t local_cap;
  int64_t *order; /* 2 per point: storage index, point; ascending */
  size_t order_cap;
} sph_verdict;

sph_status sph_verdict_create(sph_verdict **out, const sph_sim *sim,
                              sph_error *err);
/* stability_check.c: the counts and flags a checkpoint restored are in
 * range (SPH_ERR_IO otherwise) */
sph_status sph_verdict_check_restored(const sph_verdict *v, sph_error *err);
void sph_verdict_destroy(sph_verdict *v);

/* Updates the indicators from a frame (after method->derive); fails only
 * when the neighbour lists cannot grow. Over MPI ranks (the frame's sim has
 * a domain, its ps the owned particles) every rank calls it: the same
 * verdict on all. */
sph_status sph_verdict_observe(sph_verdict *v, const sph_frame *frame,
                               sph_error *err);

/* stability_rest.c: `energy_growth` when a free body (no boundary, wall
 * or external work) that started at rest or translating rigidly holds a
 * kinetic energy relative to its mean velocity above the energy floor (E:
 * the frame's kinetic + strain energy, lin: its linear momentum) */
void sph_verdict_energy_from_rest(sph_verdict *v, const sph_frame *frame,
                                  double E, const double lin[3]);

/* Records that indicator i tripped at time t; the first one marks the run
 * unstable with its reason. */
void sph_verdict_fail(sph_verdict *v, sph_indicator i, double t,
                      const char *reason);

/* A time step that failed at time t with err: `nan` for a non-finite value,
 * `step` for any other reason. */
void sph_verdict_fail_step(sph_verdict *v, double t, const sph_error *err);

/* The checkerboard indicator C of field f (see above); NaN when no particle
 * has a parity. */
double sph_checkerboard_indicator(const signed char *parity,
                                  const double *volume, const double *f,
                                  size_t n);
/* The same over MPI ranks, each passing its owned particles' values
 * (sums added in rank order); d NULL: sph_checkerboard_indicator. */
double sph_checkerboard_indicator_over(sph_domain *d, const signed char *parity,
                                       const double *volume, const double *f,
                                       size_t n);

/* Lattice parity of every particle of a scene's bodies. */
void sph_lattice_parity(const sph_scene *s, const sph_particles *ps,
                        signed char *parity);

/* Which sph ran and how it was called (summary.json, scene_used.yaml). */
typedef struct sph_provenance {
  const char *version; /* project version */
  const char *commit;  /* git describe at configure time, or "unknown" */
  const char *command; /* the command line, words joined by spaces */
} sph_provenance;

/* summary.json (keys documented in the README): ref holds the errors
 * against the scene's reference (NULL: none); `sinks` holds the wall
 * seconds of each of the nsinks sinks; mp4_seconds >= 0 adds the time the
 * mp4 took to assemble; stopped_by names the signal that stopped the run
 * (NULL: none). */
sph_status sph_summary_write(const char *path, const sph_sim *sim,
                             const sph_provenance *prov, const sph_verdict *v,
                             const sph_reference_error *ref,
                             double wall_seconds, const sph_sink *sinks,
                             int nsinks, double mp4_seconds, int completed,
                             const char *stopped_by, sph_error *err);

#endif
