/* The PNG sink rendering on the calling thread (render/png_sink.c): the
 * same frames as sph_png_sink_ops, each drawn, composited and written
 * inside `write` with the GL context current on the caller. The reference
 * the threaded sink is tested against (tests/unit/test_png_async.c). */
#ifndef SPH_RENDER_PNG_SINK_IMPL_H
#define SPH_RENDER_PNG_SINK_IMPL_H

#include "sph/sink.h"

extern const sph_sink_ops sph_png_sink_sync_ops;

#endif
