/* sph study: the cases of a parameter study, their result rows, and the
 * results.csv / report.md / gnuplot writers shared by cmd_study.c and
 * study_report.c. */
#ifndef SPH_STUDY_IMPL_H
#define SPH_STUDY_IMPL_H

#include <stdio.h>

#include "sph/status.h"

#define STUDY_MAX_KEYS 8
#define STUDY_MAX_VALUES 64
#define STUDY_NORMS 7

extern const char *const study_norm_names[STUDY_NORMS];

/* What one case's run gave (wall is the median over the repeats). */
typedef struct study_row {
  long particles;
  double dp;
  unsigned long steps;
  double wall, rate;
  double l2[STUDY_NORMS]; /* errors; NAN where the reference gives none */
  double period;          /* a period reference's measured period, or NAN */
  double energy_drift, lin_drift, ang_drift;
  int stable;
  char reason[256];
} study_row;

typedef struct study_case {
  int index;
  const char *values[STUDY_MAX_KEYS]; /* one per --vary key */
  double dp;                          /* from the validated scene */
  long particles;
  int done; /* row holds a result (this session or results.csv) */
  study_row row;
} study_case;

typedef struct study {
  const char *scene_path;
  char scene_name[64];
  const char *keys[STUDY_MAX_KEYS];
  int nkeys;
  int resolution; /* index into keys of the resolution axis */
  study_case *cases;
  int ncases;
  int repeat, threads;
  char dir[1024];
} study;

/* The results.csv header line (no newline). */
void study_csv_header(const study *s, FILE *f);
/* One results.csv row of case c (with newline). */
void study_csv_row(const study *s, const study_case *c, FILE *f);
/* Reads results.csv at path: marks the cases whose row is there done and
 * fills their rows. SPH_ERR_IO when absent; SPH_ERR_ARG when its header is
 * not this study's. Lines cut short by a kill are dropped. */
sph_status study_csv_read(study *s, const char *path, sph_error *err);

/* Writes DIR/report.md (atomically). */
sph_status study_report_write(const study *s, sph_error *err);
/* Writes DIR/plots.gp and runs gnuplot on it (fork/exec), the images under
 * a temporary name renamed into place. SPH_ERR_UNSUPPORTED when gnuplot is
 * not on PATH. */
sph_status study_plots_write(const study *s, sph_error *err);

/* Least-squares slope of log y against log x over the pairs with finite,
 * positive values; returns the number of points used (NAN slope when fewer
 * than two distinct x). */
int study_fit_order(const double *x, const double *y, int n, double *slope,
                    double *intercept);

#endif
