/* Progress display of sph run: one updating bar with ETA on a terminal, a
 * plain line per output otherwise. */
#ifndef SPH_PROGRESS_IMPL_H
#define SPH_PROGRESS_IMPL_H

typedef struct sph_progress {
  int tty, quiet;
  double t_end, wall0, last;
} sph_progress;

void sph_progress_start(sph_progress *p, double t_end, int quiet);
/* After a step: redraws the bar on a terminal (at most 5 times a second). */
void sph_progress_step(sph_progress *p, double t, unsigned long steps);
/* At an output time: a plain line when not on a terminal. */
void sph_progress_output(sph_progress *p, double t, unsigned long steps);
void sph_progress_finish(sph_progress *p);

#endif
