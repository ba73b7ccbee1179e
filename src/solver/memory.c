/* The memory a run may take (no paper: resource limits, issue 36): the
 * smallest of --max-memory, 90 % of /proc/meminfo's MemAvailable, the memory
 * cgroup's limit less its usage (v2 memory.max and memory.current, v1
 * memory.limit_in_bytes and memory.usage_in_bytes, of the process's own
 * cgroup from /proc/self/cgroup and of each cgroup above it, under
 * $SPH_CGROUP_ROOT or /sys/fs/cgroup) and RLIMIT_AS less the address space in
 * use (VmSize). A memory cgroup kills a process past its limit without a
 * word, so its limit is checked before anything is allocated. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "solver/memory.h"

/* the first number in file after prefix (whole file when prefix is ""); -1
 * when absent or "max" */
static double read_number(const char *file, const char *prefix) {
  FILE *f = fopen(file, "r");
  if (!f)
    return -1.0;
  char line[256];
  double v = -1.0;
  size_t n = strlen(prefix);
  while (fgets(line, sizeof line, f))
    if (strncmp(line, prefix, n) == 0) {
      char *end;
      v = strtod(line + n, &end);
      if (end == line + n)
        v = -1.0;
      break;
    }
  fclose(f);
  return v;
}

/* v2 (controller "") or v1 ("memory"): the tightest limit less usage over
 * the cgroup `path` and its ancestors under root/sub; -1 without one */
static double cgroup_room(const char *root, const char *sub, const char *path,
                          const char *max_name, const char *cur_name,
                          double *limit) {
  char dir[1024];
  double room = -1.0;
  snprintf(dir, sizeof dir, "%s%s%s", root, sub, path);
  size_t base = strlen(root) + strlen(sub);
  for (;;) {
    char file[1200];
    size_t len = strlen(dir);
    while (len > base && dir[len - 1] == '/')
      dir[--len] = '\0';
    snprintf(file, sizeof file, "%s/%s", dir, max_name);
    double max = read_number(file, "");
    if (max > 0.0 && max < 1e18) { /* v1 writes "no limit" as ~2^63 */
      snprintf(file, sizeof file, "%s/%s", dir, cur_name);
      double cur = read_number(file, "");
      double r = max - (cur > 0.0 ? cur : 0.0);
      if (room < 0.0 || r < room) {
        room = r > 1.0 ? r : 1.0;
        *limit = max;
      }
    }
    char *slash = strrchr(dir, '/');
    if (len <= base || !slash || (size_t)(slash - dir) < base)
      break;
    *slash = '\0';
  }
  return room;
}

/* the memory cgroup's room (bytes) and limit; -1 without a limit */
static double cgroup(double *limit) {
  const char *root = getenv("SPH_CGROUP_ROOT");
  root = root && *root ? root : "/sys/fs/cgroup";
  FILE *f = fopen("/proc/self/cgroup", "r");
  char line[1024], v1[1024] = "", v2[1024] = "";
  int has_v1 = 0, has_v2 = 0;
  while (f && fgets(line, sizeof line, f)) {
    line[strcspn(line, "\n")] = '\0';
    char *c1 = strchr(line, ':'), *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
    if (!c2)
      continue;
    *c2 = '\0';
    const char *ctl = c1 + 1;
    if (strcmp(line, "0") == 0 && *ctl == '\0') {
      snprintf(v2, sizeof v2, "%s", c2 + 1);
      has_v2 = 1;
    }
    for (const char *p = ctl; *p;) { /* "memory" in a comma list */
      size_t n = strcspn(p, ",");
      if (n == 6 && strncmp(p, "memory", 6) == 0) {
        snprintf(v1, sizeof v1, "%s", c2 + 1);
        has_v1 = 1;
      }
      p += n + (p[n] == ',');
    }
  }
  if (f)
    fclose(f);
  double room = -1.0, l2 = 0.0, l1 = 0.0;
  double r2 = cgroup_room(root, "", has_v2 ? v2 : "/", "memory.max",
                          "memory.current", &l2);
  double r1 =
      cgroup_room(root, "/memory", has_v1 ? v1 : "/", "memory.limit_in_bytes",
                  "memory.usage_in_bytes", &l1);
  if (r2 >= 0.0) {
    room = r2;
    *limit = l2;
  }
  if (r1 >= 0.0 && (room < 0.0 || r1 < room)) {
    room = r1;
    *limit = l1;
  }
  return room;
}

/* sizes as "400 MB" or "1.5 GB" */
static void size_text(double b, char *buf, size_t n) {
  if (b >= 1e9)
    snprintf(buf, n, "%.3g GB", b / 1e9);
  else
    snprintf(buf, n, "%.0f MB", b / 1e6);
}

void sph_memory_limit_get(double max_memory, sph_memory_limit *lim) {
  memset(lim, 0, sizeof *lim);
  double avail = read_number("/proc/meminfo", "MemAvailable:");
  if (avail > 0.0) { /* kB */
    lim->bytes = 0.9 * avail * 1024.0;
    snprintf(lim->what, sizeof lim->what, "%.1f GB of memory is available",
             avail * 1024.0 / 1e9);
  }
  if (max_memory > 0.0 && !(lim->bytes > 0.0 && lim->bytes < max_memory)) {
    lim->bytes = max_memory;
    lim->by_option = 1;
    snprintf(lim->what, sizeof lim->what, "the limit (--max-memory) is %.3g GB",
             max_memory / 1e9);
  }
  char a[32], b[32];
  double climit = 0.0, croom = cgroup(&climit);
  if (croom >= 0.0 && (!(lim->bytes > 0.0) || croom < lim->bytes)) {
    lim->bytes = croom;
    lim->by_option = 0;
    size_text(climit, a, sizeof a);
    size_text(croom, b, sizeof b);
    snprintf(lim->what, sizeof lim->what,
             "the memory cgroup's limit of %s leaves %s", a, b);
  }
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
    double used = read_number("/proc/self/status", "VmSize:") * 1024.0;
    double room = (double)rl.rlim_cur - (used > 0.0 ? used : 0.0);
    room = room > 1.0 ? room : 1.0;
    if (!(lim->bytes > 0.0) || room < lim->bytes) {
      lim->bytes = room;
      lim->by_option = 0;
      size_text((double)rl.rlim_cur, a, sizeof a);
      size_text(room, b, sizeof b);
      snprintf(lim->what, sizeof lim->what,
               "the address-space limit (ulimit -v) of %s leaves %s", a, b);
    }
  }
}
