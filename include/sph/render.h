/* The off-screen renderer's sink (render/png_sink.c): pressure-coloured
 * sphere frames, frames/<scene>_NNNN.png, created only when the scene has
 * an `output.png` block. */
#ifndef SPH_RENDER_H
#define SPH_RENDER_H

#include "sph/sink.h"

extern const sph_sink_ops sph_png_sink_ops;

#endif
