/* The animation after a run: frames/<scene>_NNNN.png assembled into
 * <scene>.mp4 by the ffmpeg found on PATH (spawned without a shell, its
 * stdin from /dev/null and its output captured, never printed), written
 * under a temporary name and renamed. */
#include <errno.h>
#include <fcntl.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "render/render.h"

extern char **environ;

/* Captured output kept per ffmpeg call (the encoder list is about 30 kB). */
#define CAPTURE_MAX (1 << 20)

/* The executable `prog` in a folder of PATH, into out; 0 when there is none. */
static int find_on_path(const char *prog, char *out, size_t size) {
  const char *path = getenv("PATH");
  if (!path || !*path)
    return 0;
  for (const char *p = path;;) {
    const char *end = strchr(p, ':');
    size_t len = end ? (size_t)(end - p) : strlen(p);
    struct stat st;
    if (len == 0)
      snprintf(out, size, "./%s", prog);
    else
      snprintf(out, size, "%.*s/%s", (int)len, p, prog);
    if (stat(out, &st) == 0 && S_ISREG(st.st_mode) && access(out, X_OK) == 0)
      return 1;
    if (!end)
      return 0;
    p = end + 1;
  }
}

/* Runs argv (argv[0] a path) with stdin from /dev/null and stdout and
 * stderr captured into *out (malloc'd, NUL-terminated, at most CAPTURE_MAX
 * bytes kept); *status is the waitpid status. */
static sph_status run(char *const *argv, char **out, int *status,
                      sph_error *err) {
  int fd[2];
  *out = NULL;
  if (pipe2(fd, O_CLOEXEC) != 0)
    return sph_error_set(err, SPH_ERR_IO, "cannot start %s: %s", argv[0],
                         strerror(errno));
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&fa, fd[1], 1);
  posix_spawn_file_actions_adddup2(&fa, fd[1], 2);
  pid_t pid;
  int rc = posix_spawn(&pid, argv[0], &fa, NULL, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  close(fd[1]);
  if (rc != 0) {
    close(fd[0]);
    return sph_error_set(err, SPH_ERR_IO, "cannot start %s: %s", argv[0],
                         strerror(rc));
  }
  /* read to the end (the child never blocks on a full pipe), then reap */
  size_t len = 0, cap = 4096;
  char *buf = malloc(cap);
  for (;;) {
    char chunk[4096];
    ssize_t got = read(fd[0], chunk, sizeof chunk);
    if (got < 0 && errno == EINTR)
      continue;
    if (got <= 0)
      break;
    if (buf && len + (size_t)got + 1 > cap && cap < CAPTURE_MAX) {
      size_t want = 2 * cap + (size_t)got;
      char *grown = realloc(buf, want);
      if (grown) {
        buf = grown;
        cap = want;
      }
    }
    if (buf && len + (size_t)got + 1 <= cap) {
      memcpy(buf + len, chunk, (size_t)got);
      len += (size_t)got;
    }
  }
  close(fd[0]);
  while (waitpid(pid, status, 0) < 0)
    if (errno != EINTR) {
      free(buf);
      return sph_error_set(err, SPH_ERR_IO, "waiting for %s: %s", argv[0],
                           strerror(errno));
    }
  if (buf)
    buf[len] = '\0';
  *out = buf;
  return SPH_OK;
}

/* The last non-empty line of text, into line. */
static void last_line(const char *text, char *line, size_t size) {
  const char *end = text + strlen(text);
  while (end > text && (end[-1] == '\n' || end[-1] == '\r' || end[-1] == ' '))
    --end;
  const char *start = end;
  while (start > text && start[-1] != '\n' && start[-1] != '\r')
    --start;
  snprintf(line, size, "%.*s", (int)(end - start), start);
}

/* Whether this ffmpeg has the libx264 encoder. */
static int has_libx264(const char *ffmpeg) {
  char *argv[] = {(char *)ffmpeg, "-hide_banner", "-nostdin", "-loglevel",
                  "error",        "-encoders",    NULL};
  char *out;
  int status, yes = 0;
  if (run(argv, &out, &status, NULL) != SPH_OK)
    return 0;
  yes = out && WIFEXITED(status) && WEXITSTATUS(status) == 0 &&
        strstr(out, " libx264 ");
  free(out);
  return yes;
}

sph_status sph_mp4_assemble(const char *dir, const char *scene, int frames,
                            double fps, sph_mp4_info *info, sph_error *err) {
  memset(info, 0, sizeof *info);
  if (frames < 1)
    return sph_error_set(err, SPH_ERR_ARG, "mp4: no frames to assemble");
  char ffmpeg[1024];
  if (!find_on_path("ffmpeg", ffmpeg, sizeof ffmpeg))
    return sph_error_set(err, SPH_ERR_UNSUPPORTED, "ffmpeg not found on PATH");
  double t0 = sph_wtime();
  /* the input pattern, with any % of the folder doubled for ffmpeg */
  char pattern[2200], part[1200], rate[32], count[32];
  size_t k = 0;
  for (const char *c = dir; *c && k + 3 < sizeof pattern; ++c) {
    if (*c == '%')
      pattern[k++] = '%';
    pattern[k++] = *c;
  }
  snprintf(pattern + k, sizeof pattern - k, "/frames/%s_%%04d.png", scene);
  snprintf(info->path, sizeof info->path, "%s/%s.mp4", dir, scene);
  snprintf(part, sizeof part, "%s.part", info->path);
  snprintf(rate, sizeof rate, "%.6g", fps);
  snprintf(count, sizeof count, "%d", frames);
  /* ffmpeg opens the .part by name: no link under either name (issue 36) */
  struct stat ls;
  const char *names[2] = {info->path, part};
  for (int i = 0; i < 2; ++i)
    if (lstat(names[i], &ls) == 0 && !S_ISREG(ls.st_mode))
      return sph_error_at(err, SPH_ERR_IO, names[i], 0, 0, NULL,
                          "not a regular file (a symbolic link?); sph does "
                          "not write through links: remove it");
  remove(part);
  int x264 = has_libx264(ffmpeg);
  snprintf(info->codec, sizeof info->codec, "%s", x264 ? "libx264" : "mpeg4");
  info->frames = frames;
  info->fps = fps;
  /* x264's veryfast preset: 45 % less time than its default, 3 % more bytes
   * (the twisting column's 61 frames, same crf) */
  static char *x264_quality[] = {"-preset", "veryfast", "-crf", "20"};
  static char *mpeg4_quality[] = {"-q:v", "3", "-g", "12"};
  char **quality = x264 ? x264_quality : mpeg4_quality;
  char *argv[] = {ffmpeg,
                  "-hide_banner",
                  "-loglevel",
                  "error",
                  "-nostdin",
                  "-y",
                  "-framerate",
                  rate,
                  "-start_number",
                  "0",
                  "-i",
                  pattern,
                  "-frames:v",
                  count,
                  "-vf",
                  "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                  "-c:v",
                  info->codec,
                  "-pix_fmt",
                  "yuv420p",
                  quality[0],
                  quality[1],
                  quality[2],
                  quality[3],
                  "-movflags",
                  "+faststart",
                  "-f",
                  "mp4",
                  part,
                  NULL};
  char *out;
  int status;
  sph_status st = run(argv, &out, &status, err);
  info->seconds = sph_wtime() - t0;
  if (st != SPH_OK)
    return st;
  char line[512] = "";
  if (out)
    last_line(out, line, sizeof line);
  free(out);
  struct stat sb;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    remove(part);
    if (WIFSIGNALED(status))
      return sph_error_set(err, SPH_ERR_IO, "ffmpeg killed by signal %d",
                           WTERMSIG(status));
    return sph_error_set(err, SPH_ERR_IO, "ffmpeg failed (exit %d)%s%s",
                         WEXITSTATUS(status), *line ? ": " : "", line);
  }
  if (stat(part, &sb) != 0 || sb.st_size == 0) {
    remove(part);
    return sph_error_set(err, SPH_ERR_IO, "ffmpeg wrote no video%s%s",
                         *line ? ": " : "", line);
  }
  if (rename(part, info->path) != 0) {
    int e = errno;
    remove(part);
    return sph_error_at(err, SPH_ERR_IO, info->path, 0, 0, NULL,
                        "cannot rename the video into place: %s", strerror(e));
  }
  return SPH_OK;
}
