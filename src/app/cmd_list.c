/* sph list: the shipped scenes, one line each (name, method, dimension and
 * the scene's first comment line, which cites its benchmark). */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/app_impl.h"
#include "scene/scene.h"

static int cmp_str(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

static void first_comment(const char *path, char *buf, size_t size) {
  buf[0] = '\0';
  FILE *f = fopen(path, "r");
  if (!f)
    return;
  char line[1024];
  while (fgets(line, sizeof line, f)) {
    if (line[0] != '#')
      continue;
    char *s = line + 1;
    while (*s == ' ')
      ++s;
    s[strcspn(s, "\r\n")] = '\0';
    snprintf(buf, size, "%.*s", (int)size - 1, s);
    break;
  }
  fclose(f);
}

static const int list_allowed[] = {0};
static const sph_app_command list_command = {
    "list",
    "usage: sph list\n"
    "  the shipped scenes (run one by name: sph run NAME), one line each\n",
    list_allowed, NULL, NULL};

size_t sph_app_scene_files(char **names, size_t max) {
  DIR *d = opendir(sph_app_scenes_dir());
  if (!d)
    return 0;
  size_t n = 0;
  struct dirent *e;
  while ((e = readdir(d)) && n < max) {
    size_t len = strlen(e->d_name);
    if (len > 5 && !strcmp(e->d_name + len - 5, ".yaml"))
      names[n++] = strdup(e->d_name);
  }
  closedir(d);
  qsort(names, n, sizeof *names, cmp_str);
  return n;
}

int sph_cmd_list(int argc, char **argv) {
  int rc = sph_app_getopt(&list_command, argc, argv, NULL);
  if (rc != SPH_EXIT_OK)
    return rc == SPH_APP_HELP ? SPH_EXIT_OK : rc;
  const char *dir = sph_app_scenes_dir();
  char *names[512];
  size_t n = sph_app_scene_files(names, 512);
  if (!n) {
    fprintf(stderr, "sph list: no scene in the scenes folder %s\n", dir);
    return SPH_EXIT_IO;
  }
  int bad = 0;
  for (size_t i = 0; i < n; ++i) {
    char path[1024], comment[256];
    snprintf(path, sizeof path, "%s/%s", dir, names[i]);
    first_comment(path, comment, sizeof comment);
    sph_error err;
    sph_scene *s = NULL;
    if (sph_scene_load(&s, path, NULL, 0, &err) == SPH_OK) {
      printf("%-34s %-8s %dD  %s\n", s->name, s->method_name, s->dimension,
             comment);
    } else {
      char msg[1024];
      sph_error_format(&err, msg, sizeof msg);
      printf("%-34s INVALID  %s\n", names[i], msg);
      bad = 1;
    }
    sph_scene_destroy(s);
    free(names[i]);
  }
  return bad ? SPH_EXIT_FAIL : SPH_EXIT_OK;
}
