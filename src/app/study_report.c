/* sph study outputs: results.csv rows (written and read back for --resume),
 * report.md with the fitted convergence orders, and the gnuplot script that
 * draws error_vs_time.png and convergence.png. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "app/study_impl.h"
#include "io/sink.h"

const char *const study_norm_names[STUDY_NORMS] = {
    "l2_velocity",          "l2_stress",    "l2_displacement",
    "h1_displacement",      "period_error", "l2_displacement_gauss",
    "h1_displacement_gauss"};

static const char *const fixed_columns[] = {"particles",
                                            "dp",
                                            "steps",
                                            "wall_seconds",
                                            "particle_steps_per_second",
                                            "l2_velocity",
                                            "l2_stress",
                                            "l2_displacement",
                                            "h1_displacement",
                                            "period_error",
                                            "l2_displacement_gauss",
                                            "h1_displacement_gauss",
                                            "period",
                                            "energy_drift",
                                            "linear_momentum_drift",
                                            "angular_momentum_drift",
                                            "stable",
                                            "reason",
                                            NULL};
#define NFIXED 18

static void csv_field(FILE *f, const char *s) {
  if (!strpbrk(s, ",\"\n")) {
    fputs(s, f);
    return;
  }
  fputc('"', f);
  for (; *s; ++s) {
    if (*s == '"')
      fputc('"', f);
    fputc(*s == '\n' ? ' ' : *s, f);
  }
  fputc('"', f);
}

static void csv_number(FILE *f, double x) {
  if (isfinite(x))
    fprintf(f, ",%.6g", x);
  else
    fputc(',', f);
}

void study_csv_header(const study *s, FILE *f) {
  for (int k = 0; k < s->nkeys; ++k) {
    csv_field(f, s->keys[k]);
    fputc(',', f);
  }
  for (int i = 0; fixed_columns[i]; ++i)
    fprintf(f, "%s%s", i ? "," : "", fixed_columns[i]);
}

void study_csv_row(const study *s, const study_case *c, FILE *f) {
  const study_row *r = &c->row;
  for (int k = 0; k < s->nkeys; ++k) {
    csv_field(f, c->values[k]);
    fputc(',', f);
  }
  fprintf(f, "%ld", r->particles);
  csv_number(f, r->dp);
  fprintf(f, ",%lu", r->steps);
  csv_number(f, r->wall);
  csv_number(f, r->rate);
  for (int k = 0; k < STUDY_NORMS; ++k)
    csv_number(f, r->l2[k]);
  csv_number(f, r->period);
  csv_number(f, r->energy_drift);
  csv_number(f, r->lin_drift);
  csv_number(f, r->ang_drift);
  fprintf(f, ",%s,", r->stable ? "true" : "false");
  csv_field(f, r->reason);
  fputc('\n', f);
}

/* Splits one CSV line in place (quotes honoured); returns the count. */
static int csv_split(char *line, char **fields, int max) {
  int n = 0;
  char *p = line;
  while (n < max) {
    char *out = p;
    fields[n++] = p;
    if (*p == '"') {
      char *q = p + 1;
      for (;;) {
        if (!*q)
          break;
        if (*q == '"' && q[1] == '"') {
          *out++ = '"';
          q += 2;
        } else if (*q == '"') {
          ++q;
          break;
        } else
          *out++ = *q++;
      }
      p = q;
    } else {
      while (*p && *p != ',')
        *out++ = *p++;
    }
    char sep = *p;
    *out = '\0';
    if (sep != ',')
      break;
    ++p;
  }
  return n;
}

static double field_number(const char *s) {
  char *end;
  double x = strtod(s, &end);
  return *s && !*end ? x : NAN;
}

sph_status study_csv_read(study *s, const char *path, sph_error *err) {
  FILE *f = fopen(path, "r");
  if (!f)
    return sph_error_set(err, SPH_ERR_IO, "%s: %s", path, strerror(errno));
  char line[8192], header[8192];
  char *fields[STUDY_MAX_KEYS + NFIXED + 1];
  int ncols = s->nkeys + NFIXED;
  FILE *h = fmemopen(header, sizeof header, "w");
  study_csv_header(s, h);
  fputc('\0', h);
  fclose(h);
  if (!fgets(line, sizeof line, f) || strcspn(line, "\n") != strlen(header) ||
      strncmp(line, header, strlen(header))) {
    fclose(f);
    return sph_error_set(err, SPH_ERR_ARG,
                         "%s: the columns are not those of this study "
                         "(other --vary keys?); use another --out",
                         path);
  }
  while (fgets(line, sizeof line, f)) {
    size_t len = strlen(line);
    if (!len || line[len - 1] != '\n')
      break; /* cut short by a kill */
    line[len - 1] = '\0';
    if (csv_split(line, fields, ncols + 1) != ncols)
      continue;
    for (int i = 0; i < s->ncases; ++i) {
      study_case *c = &s->cases[i];
      int same = 1;
      for (int k = 0; k < s->nkeys && same; ++k)
        same = !strcmp(c->values[k], fields[k]);
      if (!same)
        continue;
      char **v = fields + s->nkeys;
      study_row *r = &c->row;
      r->particles = (long)field_number(v[0]);
      r->dp = field_number(v[1]);
      r->steps = (unsigned long)field_number(v[2]);
      r->wall = field_number(v[3]);
      r->rate = field_number(v[4]);
      int j = 5;
      for (int k = 0; k < STUDY_NORMS; ++k)
        r->l2[k] = field_number(v[j++]);
      r->period = field_number(v[j++]);
      r->energy_drift = field_number(v[j++]);
      r->lin_drift = field_number(v[j++]);
      r->ang_drift = field_number(v[j++]);
      r->stable = !strcmp(v[j++], "true");
      snprintf(r->reason, sizeof r->reason, "%s", v[j]);
      c->done = 1;
      break;
    }
  }
  fclose(f);
  return SPH_OK;
}

int study_fit_order(const double *x, const double *y, int n, double *slope,
                    double *intercept) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int m = 0;
  for (int i = 0; i < n; ++i)
    if (isfinite(x[i]) && isfinite(y[i]) && x[i] > 0 && y[i] > 0) {
      double lx = log(x[i]), ly = log(y[i]);
      sx += lx;
      sy += ly;
      sxx += lx * lx;
      sxy += lx * ly;
      ++m;
    }
  double det = m * sxx - sx * sx;
  if (m < 2 || !(fabs(det) > 1e-12 * (sxx * m + 1e-300))) {
    *slope = *intercept = NAN;
    return m;
  }
  *slope = (m * sxy - sx * sy) / det;
  *intercept = (sy - *slope * sx) / m;
  return m;
}

/* Whether cases a and b differ only in the resolution key. */
static int same_series(const study *s, const study_case *a,
                       const study_case *b) {
  for (int k = 0; k < s->nkeys; ++k)
    if (k != s->resolution && strcmp(a->values[k], b->values[k]))
      return 0;
  return 1;
}

/* The short name of a varied key: its last component ("method.fields" ->
 * "fields"), or its last two when another key ends the same way. */
static const char *key_short(const study *s, int k, char *buf, size_t len) {
  const char *key = s->keys[k], *dot = strrchr(key, '.');
  const char *last = dot ? dot + 1 : key;
  for (int j = 0; j < s->nkeys; ++j) {
    const char *o = strrchr(s->keys[j], '.');
    if (j != k && !strcmp(o ? o + 1 : s->keys[j], last) && dot) {
      const char *prev = dot;
      while (prev > key && prev[-1] != '.')
        --prev;
      snprintf(buf, len, "%s", prev);
      return buf;
    }
  }
  snprintf(buf, len, "%s", last);
  return buf;
}

/* A value as a legend shows it: YAML braces and quotes dropped, spaces
 * after ':' and ',' kept single ("{name: tl-csph}" -> "name: tl-csph"). */
static void value_short(const char *v, char *buf, size_t len) {
  size_t n = 0;
  for (; *v && n + 1 < len; ++v)
    if (*v != '{' && *v != '}' && *v != '"' && *v != '\'')
      buf[n++] = *v;
  buf[n] = '\0';
}

/* Whether key k takes more than one value among the series leads. */
static int key_varies(const study *s, int k, const int *leads, int nlead) {
  for (int j = 1; j < nlead; ++j)
    if (strcmp(s->cases[leads[j]].values[k], s->cases[leads[0]].values[k]))
      return 1;
  return 0;
}

/* report.md: every key but the resolution one, in full */
static void series_label(const study *s, const study_case *c, char *buf,
                         size_t len) {
  buf[0] = '\0';
  for (int k = 0; k < s->nkeys; ++k) {
    if (k == s->resolution)
      continue;
    size_t used = strlen(buf);
    snprintf(buf + used, len - used, "%s%s=%s", used ? " " : "", s->keys[k],
             c->values[k]);
  }
  if (!buf[0])
    snprintf(buf, len, "all");
}

/* a plot's legend: the short names and values of the keys that differ
 * between the series */
static void series_legend(const study *s, const study_case *c, const int *leads,
                          int nlead, char *buf, size_t len) {
  buf[0] = '\0';
  for (int k = 0; k < s->nkeys; ++k) {
    if (k == s->resolution || !key_varies(s, k, leads, nlead))
      continue;
    char name[128], value[256];
    size_t used = strlen(buf);
    value_short(c->values[k], value, sizeof value);
    snprintf(buf + used, len - used, "%s%s %s", used ? ", " : "",
             key_short(s, k, name, sizeof name), value);
  }
  if (!buf[0])
    snprintf(buf, len, "%s", s->scene_name);
}

/* Which norms any finished run reports. */
static void norms_present(const study *s, int present[STUDY_NORMS]) {
  for (int k = 0; k < STUDY_NORMS; ++k) {
    present[k] = 0;
    for (int i = 0; i < s->ncases; ++i)
      if (s->cases[i].done && isfinite(s->cases[i].row.l2[k]))
        present[k] = 1;
  }
}

/* The fit of norm k over the stable runs of the series led by `lead`. */
static int series_fit(const study *s, int lead, int k, double *order,
                      double *c0) {
  double x[STUDY_MAX_VALUES], y[STUDY_MAX_VALUES];
  int n = 0;
  for (int i = lead; i < s->ncases && n < STUDY_MAX_VALUES; ++i) {
    const study_case *c = &s->cases[i];
    if (same_series(s, &s->cases[lead], c) && c->done && c->row.stable) {
      x[n] = c->row.dp;
      y[n++] = c->row.l2[k];
    }
  }
  return study_fit_order(x, y, n, order, c0);
}

/* Index of the first case of each series (cases with the same non-resolution
 * values); returns the count. */
static int series_leads(const study *s, int *leads) {
  int n = 0;
  for (int i = 0; i < s->ncases; ++i) {
    int seen = 0;
    for (int j = 0; j < n && !seen; ++j)
      seen = same_series(s, &s->cases[leads[j]], &s->cases[i]);
    if (!seen)
      leads[n++] = i;
  }
  return n;
}

static void md_number(FILE *f, double x) {
  if (isfinite(x))
    fprintf(f, " %.3g |", x);
  else
    fputs(" |", f);
}

sph_status study_report_write(const study *s, sph_error *err) {
  char path[1100];
  snprintf(path, sizeof path, "%s/report.md", s->dir);
  sph_atomic_file af;
  SPH_TRY(sph_atomic_open(&af, path, err));
  FILE *f = af.f;
  fprintf(f,
          "# Study of %s\n\nScene `%s`, %d case%s, wall time the median "
          "of %d repeat%s.\n\n",
          s->scene_name, s->scene_path, s->ncases, s->ncases == 1 ? "" : "s",
          s->repeat, s->repeat == 1 ? "" : "s");
  /* the error columns some run reports, the period if measured */
  int present[STUDY_NORMS], has_period = 0, ncols = s->nkeys + 10;
  norms_present(s, present);
  for (int i = 0; i < s->ncases; ++i)
    has_period |= s->cases[i].done && isfinite(s->cases[i].row.period);
  fputs("|", f);
  for (int k = 0; k < s->nkeys; ++k)
    fprintf(f, " %s |", s->keys[k]);
  fputs(" particles | dp | steps | wall s | particle-steps/s |", f);
  for (int k = 0; k < STUDY_NORMS; ++k)
    if (present[k]) {
      fprintf(f, " %s |", study_norm_names[k]);
      ++ncols;
    }
  if (has_period) {
    fputs(" period |", f);
    ++ncols;
  }
  fputs(" energy drift | lin. mom. drift | ang. mom. drift | stable | reason "
        "|\n|",
        f);
  for (int k = 0; k < ncols; ++k)
    fputs("---|", f);
  fputc('\n', f);
  for (int i = 0; i < s->ncases; ++i) {
    const study_case *c = &s->cases[i];
    if (!c->done)
      continue;
    const study_row *r = &c->row;
    fputs("|", f);
    for (int k = 0; k < s->nkeys; ++k)
      fprintf(f, " `%s` |", c->values[k]);
    fprintf(f, " %ld |", r->particles);
    md_number(f, r->dp);
    fprintf(f, " %lu |", r->steps);
    md_number(f, r->wall);
    md_number(f, r->rate);
    for (int k = 0; k < STUDY_NORMS; ++k)
      if (present[k])
        md_number(f, r->l2[k]);
    if (has_period)
      md_number(f, r->period);
    md_number(f, r->energy_drift);
    md_number(f, r->lin_drift);
    md_number(f, r->ang_drift);
    fprintf(f, " %s | %s |\n", r->stable ? "yes" : "**no**", r->reason);
  }
  fprintf(f,
          "\n## Convergence\n\nA series is the runs that differ only in "
          "`%s` (the resolution axis). The order is the least-squares slope "
          "of log(error) against log(dp) over the stable runs of the "
          "series, where dp is the particle spacing the run used (the "
          "smallest body spacing: `spacing`, or L/(n-1) for a `count` "
          "lattice, as `sph check` prints it). Energy drift is "
          "(final - initial) / |initial| total energy.\n\n",
          s->keys[s->resolution]);
  int any = 0;
  for (int k = 0; k < STUDY_NORMS; ++k)
    any |= present[k];
  if (!any)
    fputs("The scene has no `reference:` block: no error norms, no "
          "orders.\n",
          f);
  else {
    fputs("| series | runs |", f);
    for (int k = 0; k < STUDY_NORMS; ++k)
      if (present[k])
        fprintf(f, " order %s |", study_norm_names[k]);
    fputs("\n|---|---|", f);
    for (int k = 0; k < STUDY_NORMS; ++k)
      if (present[k])
        fputs("---|", f);
    fputc('\n', f);
    int leads[STUDY_MAX_VALUES * 64];
    int nlead = series_leads(s, leads);
    for (int j = 0; j < nlead; ++j) {
      char label[2048];
      series_label(s, &s->cases[leads[j]], label, sizeof label);
      int used = 0;
      double order[STUDY_NORMS], c0;
      for (int k = 0; k < STUDY_NORMS; ++k) {
        order[k] = NAN;
        if (present[k]) {
          int m = series_fit(s, leads[j], k, &order[k], &c0);
          used = m > used ? m : used;
        }
      }
      fprintf(f, "| %s | %d |", label, used);
      for (int k = 0; k < STUDY_NORMS; ++k)
        if (present[k]) {
          if (isfinite(order[k]))
            fprintf(f, " %.2f |", order[k]);
          else
            fputs(" - |", f);
        }
      fputc('\n', f);
    }
  }
  sph_status st = sph_atomic_commit(&af, err);
  if (st != SPH_OK)
    sph_atomic_abort(&af);
  return st;
}

/* gnuplot single-quoted string (quotes doubled) */
static void gp_string(FILE *f, const char *s) {
  fputc('\'', f);
  for (; *s; ++s) {
    if (*s == '\'')
      fputc('\'', f);
    fputc(*s, f);
  }
  fputc('\'', f);
}

static int find_gnuplot(char *out, size_t len) {
  const char *path = getenv("PATH");
  if (!path || !*path)
    path = "/usr/local/bin:/usr/bin:/bin";
  while (*path) {
    size_t n = strcspn(path, ":");
    snprintf(out, len, "%.*s/gnuplot", (int)n, path);
    if (n && access(out, X_OK) == 0)
      return 1;
    path += n + (path[n] == ':');
  }
  return 0;
}

/* Whether run c gives a point (x, y) of norm k: stable, finite, positive. */
static int plot_point(const study_case *c, int k, int xdp, double *x,
                      double *y) {
  *x = xdp ? c->row.dp : c->row.wall;
  *y = c->row.l2[k];
  return c->done && c->row.stable && isfinite(*x) && isfinite(*y) && *x > 0 &&
         *y > 0;
}

static int series_points(const study *s, int lead, int k, int xdp) {
  int n = 0;
  double x, y;
  for (int i = lead; i < s->ncases; ++i)
    n += same_series(s, &s->cases[lead], &s->cases[i]) &&
         plot_point(&s->cases[i], k, xdp, &x, &y);
  return n;
}

/* One datablock per series: x, y, resolution label (stable, finite runs). */
static void gp_data(FILE *f, const study *s, const int *leads, int nlead, int k,
                    int xdp) {
  for (int j = 0; j < nlead; ++j) {
    fprintf(f, "$s%d_%d_%d << EOD\n", j, k, xdp);
    for (int i = leads[j]; i < s->ncases; ++i) {
      const study_case *c = &s->cases[i];
      double x, y;
      if (!same_series(s, &s->cases[leads[j]], c) ||
          !plot_point(c, k, xdp, &x, &y))
        continue;
      fprintf(f, "%.9g %.9g \"", x, y);
      for (const char *p = c->values[s->resolution]; *p; ++p)
        if (*p != '"')
          fputc(*p, f);
      fputs("\"\n", f);
    }
    fputs("EOD\n", f);
  }
}

/* One panel per norm; xdp: error vs dp with the fits, else vs wall time. */
static void gp_figure(FILE *f, const study *s, const int *leads, int nlead,
                      const int present[STUDY_NORMS], int xdp,
                      const char *png) {
  int npanels = 0;
  for (int k = 0; k < STUDY_NORMS; ++k)
    npanels += present[k];
  fprintf(f,
          "set terminal pngcairo noenhanced size %d,600 font 'DejaVu Sans,10'\n"
          "set output ",
          520 * npanels);
  gp_string(f, png);
  fprintf(f, "\nset multiplot layout 1,%d title ", npanels);
  char title[256];
  snprintf(title, sizeof title, "%s: %s", s->scene_name,
           xdp ? "error against particle spacing" : "error against wall time");
  gp_string(f, title);
  /* the corner the data leave free: errors fall with dp, and with time */
  fprintf(f,
          "\nset logscale xy\nset grid\nset key top %s Left reverse font ',8'\n"
          "set format y '%%.0e'\n",
          xdp ? "left" : "right");
  fprintf(f, "set xlabel '%s'\n",
          xdp ? "dp (m)" : "wall time (s, median of the repeats)");
  for (int k = 0; k < STUDY_NORMS; ++k) {
    if (!present[k])
      continue;
    fprintf(f, "set ylabel '%s'\nplot ", study_norm_names[k]);
    int first = 1, labelled = 0;
    for (int j = 0; j < nlead; ++j) {
      if (!series_points(s, leads[j], k, xdp))
        continue;
      char label[2048];
      series_legend(s, &s->cases[leads[j]], leads, nlead, label, sizeof label);
      if (strlen(label) > 60) /* legends stay readable; report.md has all */
        strcpy(label + 57, "...");
      double order = NAN, c0 = NAN;
      if (xdp)
        series_fit(s, leads[j], k, &order, &c0);
      if (xdp && isfinite(order)) {
        size_t used = strlen(label);
        snprintf(label + used, sizeof label - used, " (order %.2f)", order);
      }
      fprintf(f, "%s$s%d_%d_%d using 1:2 with linespoints lc %d pt 7 title ",
              first ? "" : ", \\\n  ", j, k, xdp, j + 1);
      gp_string(f, label);
      /* the resolution labels once: the series share their x values */
      if (!labelled)
        fprintf(f,
                ", $s%d_%d_%d using 1:2:3 with labels offset 0.8,0.8 "
                "font ',7' notitle",
                j, k, xdp);
      labelled = 1;
      first = 0;
    }
    /* the fits last, drawn over the data */
    for (int j = 0; xdp && j < nlead; ++j) {
      double order = NAN, c0 = NAN;
      if (!series_points(s, leads[j], k, xdp))
        continue;
      series_fit(s, leads[j], k, &order, &c0);
      if (isfinite(order))
        fprintf(f, ", exp(%.9g)*x**%.9g with lines dt 2 lw 1.5 lc %d notitle",
                c0, order, j + 1);
    }
    fputc('\n', f);
  }
  fputs("unset multiplot\nset output\n", f);
}

sph_status study_plots_write(const study *s, sph_error *err) {
  char gnuplot[1024];
  if (!find_gnuplot(gnuplot, sizeof gnuplot))
    return sph_error_set(err, SPH_ERR_UNSUPPORTED, "gnuplot not found");
  int leads[STUDY_MAX_VALUES * 64];
  int nlead = series_leads(s, leads);
  int present[STUDY_NORMS] = {0};
  for (int k = 0; k < STUDY_NORMS; ++k)
    for (int j = 0; j < nlead; ++j)
      present[k] |= series_points(s, leads[j], k, 1) > 0;
  int any = 0;
  for (int k = 0; k < STUDY_NORMS; ++k)
    any |= present[k];
  if (!any)
    return sph_error_set(err, SPH_ERR_ARG,
                         "no stable run reports an error norm");
  char script[1100], png[2][1100], part[2][2300], log[1100];
  const char *names[2] = {"error_vs_time.png", "convergence.png"};
  snprintf(script, sizeof script, "%s/plots.gp", s->dir);
  snprintf(log, sizeof log, "%s/gnuplot.log", s->dir);
  for (int i = 0; i < 2; ++i) {
    snprintf(png[i], sizeof png[i], "%s/%s", s->dir, names[i]);
    snprintf(part[i], sizeof part[i], "%s.part", png[i]);
  }
  sph_atomic_file af;
  SPH_TRY(sph_atomic_open(&af, script, err));
  fprintf(af.f, "# sph study: the figures of %s (gnuplot %s)\n", s->dir,
          "pngcairo");
  for (int k = 0; k < STUDY_NORMS; ++k)
    if (present[k])
      for (int xdp = 0; xdp < 2; ++xdp)
        gp_data(af.f, s, leads, nlead, k, xdp);
  for (int i = 0; i < 2; ++i)
    gp_figure(af.f, s, leads, nlead, present, i, part[i]);
  sph_status st = sph_atomic_commit(&af, err);
  if (st != SPH_OK) {
    sph_atomic_abort(&af);
    return st;
  }
  fflush(stdout);
  fflush(stderr);
  pid_t pid = fork();
  if (pid == 0) {
    int l = sph_open_nofollow(log, O_WRONLY | O_CREAT | O_TRUNC, 0666, NULL);
    if (l >= 0) { /* no link followed (issue 36) */
      dup2(l, 1);
      dup2(l, 2);
      close(l);
    }
    execl(gnuplot, "gnuplot", script, (char *)NULL);
    _exit(127);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) < 0)
    return sph_error_set(err, SPH_ERR_IO, "cannot run gnuplot: %s",
                         strerror(errno));
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    for (int i = 0; i < 2; ++i)
      remove(part[i]);
    return sph_error_set(err, SPH_ERR_IO, "gnuplot failed on %s (see %s)",
                         script, log);
  }
  for (int i = 0; i < 2; ++i)
    if (rename(part[i], png[i]) != 0)
      return sph_error_set(err, SPH_ERR_IO, "%s: %s", png[i], strerror(errno));
  return SPH_OK;
}
