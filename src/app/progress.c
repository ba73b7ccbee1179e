/* Progress display for sph run (stderr). */
#include <stdio.h>
#include <unistd.h>

#include "app/progress_impl.h"
#include "solver/sim.h"

void sph_progress_start(sph_progress *p, double t_end, int quiet) {
  p->tty = isatty(fileno(stderr));
  p->quiet = quiet;
  p->t_end = t_end;
  p->wall0 = sph_wtime();
  p->last = -1.0;
}

void sph_progress_step(sph_progress *p, double t, unsigned long steps) {
  if (p->quiet || !p->tty)
    return;
  double now = sph_wtime();
  if (now - p->last < 0.2 && t < p->t_end)
    return;
  p->last = now;
  double frac = p->t_end > 0 ? t / p->t_end : 1.0;
  double wall = now - p->wall0;
  double eta = frac > 0 ? wall * (1.0 - frac) / frac : 0.0;
  char bar[31];
  int fill = (int)(frac * 30 + 0.5);
  for (int i = 0; i < 30; ++i)
    bar[i] = i < fill ? '#' : '.';
  bar[30] = '\0';
  fprintf(stderr,
          "\r[%s] %5.1f%%  t = %.4g s  step %lu  wall %.1f s  ETA %.1f s ", bar,
          100 * frac, t, steps, wall, eta);
  fflush(stderr);
}

void sph_progress_output(sph_progress *p, double t, unsigned long steps) {
  if (p->quiet || p->tty)
    return;
  fprintf(stderr, "t = %.6g / %.6g  step %lu  wall %.2f s\n", t, p->t_end,
          steps, sph_wtime() - p->wall0);
}

void sph_progress_finish(sph_progress *p) {
  if (!p->quiet && p->tty)
    fputc('\n', stderr);
}
