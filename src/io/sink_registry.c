/* The sink registry (io/sink_list.h) as a NULL-terminated array, like the
 * method registry (methods/registry.c). A file of its own, so that a test
 * can compile it again with SPH_SINK_LIST_EXTRA defined. */
#include "io/sink.h"
#include "io/sink_list.h"

#define SPH_SINK_EXTERN(name) extern const sph_sink_ops sph_##name##_sink_ops;
SPH_SINK_LIST(SPH_SINK_EXTERN)
#undef SPH_SINK_EXTERN

static const sph_sink_ops *const sinks[] = {
#define SPH_SINK_ENTRY(name) &sph_##name##_sink_ops,
    SPH_SINK_LIST(SPH_SINK_ENTRY)
#undef SPH_SINK_ENTRY
        NULL};

const sph_sink_ops *const *sph_sink_list(void) { return sinks; }
