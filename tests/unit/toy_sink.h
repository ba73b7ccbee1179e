/* What the toy sink (toy_sink.c) saw. */
#ifndef TOY_SINK_H
#define TOY_SINK_H

#define TOY_MAX_FRAMES 64

typedef struct toy_record {
  int opened, closed, frames;
  double time[TOY_MAX_FRAMES];
  int index[TOY_MAX_FRAMES];
} toy_record;

extern toy_record toy_seen;

#endif
