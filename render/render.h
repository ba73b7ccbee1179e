/* The off-screen renderer's outputs: the PNG sink (render/png_sink.c),
 * pressure-coloured sphere frames, frames/<scene>_NNNN.png, created only
 * when the scene has an `output.png` block; its pre-run check; and the mp4
 * assembled from the frames by ffmpeg after the run (render/mp4.c). */
#ifndef SPH_RENDER_H
#define SPH_RENDER_H

#include "io/sink.h"
#include "solver/sim.h"
#include "sph/status.h"

/* The png sink of the registry (io/sink_list.h): sph_png_sink_thread_ops
 * where the run's OpenMP team leaves a core free, sph_png_sink_sync_ops
 * where it takes every core. */
extern const sph_sink_ops sph_png_sink_ops;
/* Renders and writes each frame on a render thread of its own: `write`
 * copies what the frame needs and returns (waiting only while the frame
 * before is still rendering), `flush` and `close` wait until every frame is
 * written, and a render thread error comes back from the next of them;
 * thread_seconds is that thread's busy time. */
extern const sph_sink_ops sph_png_sink_thread_ops;
/* The same frames, each drawn, composited and written inside `write` on
 * the calling thread: for runs whose OpenMP team already takes every core,
 * where a render thread would compete with it (and with spinning OpenMP
 * barriers, slow it down), and the reference the threaded sink is tested
 * against (tests/unit/test_png_async.c). */
extern const sph_sink_ops sph_png_sink_sync_ops;

/* The same frames, recorded by `write` and all drawn at `close` with the
 * run-wide range and camera (sph render: nothing drawn twice). */
extern const sph_sink_ops sph_png_sink_batch_ops;

/* Checks, before anything is written, that the scene's png block can give
 * a picture: a usable camera, not inside a body (3D), a clip/cut that keeps
 * some particle, and at least one kept initial particle whose centre
 * projects inside the frame. Errors name the key (output.png.camera,
 * .camera.position or .clip) with file:line:col. SPH_OK without a block. */
sph_status sph_png_check(const sph_sim *sim, sph_error *err);

/* The value a field's diverging colour map is centred on: 0 for pressure,
 * 1 for J; NaN for the fields drawn one-sided (viridis). */
double sph_png_field_centre(int field);

/* The value a frame colours particle a by: field f of nc components
 * itself (nc 1) or its magnitude. */
double sph_png_value(const double *f, int nc, size_t a);

/* What sph_mp4_assemble did. */
typedef struct sph_mp4_info {
  char path[1100]; /* <dir>/<scene>.mp4 */
  char codec[16];  /* libx264, or mpeg4 when ffmpeg lacks libx264 */
  int frames;
  double fps;     /* frames per second: the video lasts frames / fps */
  double seconds; /* wall time of ffmpeg */
} sph_mp4_info;

/* Assembles <dir>/frames/<scene>_0000.png .. _<frames-1>.png into
 * <dir>/<scene>.mp4 with the ffmpeg found on PATH: H.264 (libx264, else
 * MPEG-4 part 2), yuv420p, dimensions padded to even, `fps` frames per
 * second. ffmpeg writes <scene>.mp4.part (forced mp4 container), which is
 * renamed on success and removed on failure. SPH_ERR_UNSUPPORTED when no
 * ffmpeg is on PATH; SPH_ERR_IO when it fails (the message carries ffmpeg's
 * last error line). ffmpeg's output never reaches the terminal. */
sph_status sph_mp4_assemble(const char *dir, const char *scene, int frames,
                            double fps, sph_mp4_info *info, sph_error *err);

#endif
