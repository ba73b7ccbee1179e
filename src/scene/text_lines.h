/* Line-by-line reading of a text file held in memory (the CSV readers of
 * cloud.c and outline_read.c): lines split in place, '#' comments cut,
 * leading blanks skipped. Private to src/scene. */
#ifndef SPH_SCENE_TEXT_LINES_H
#define SPH_SCENE_TEXT_LINES_H

#include <ctype.h>
#include <string.h>

/* Cuts the line at *cursor off the text, moves *cursor to the next line
 * (NULL after the last) and counts it in *line; returns the line without
 * its comment and leading blanks ("" for a blank line). */
static inline char *sph_text_line(char **cursor, long *line) {
  char *s = *cursor, *e = strchr(s, '\n');
  if (e)
    *e = '\0';
  *cursor = e ? e + 1 : NULL;
  ++*line;
  char *hash = strchr(s, '#');
  if (hash)
    *hash = '\0';
  while (isspace((unsigned char)*s))
    ++s;
  return s;
}

#endif
