/* The memory a run may take, from every limit the process is under. */
#ifndef SPH_SOLVER_MEMORY_H
#define SPH_SOLVER_MEMORY_H

#include <stddef.h>

/* The tightest of the limits known (bytes 0 when none is): what the caller
 * allows (max_memory, --max-memory; 0 for none), 90 % of MemAvailable, the
 * memory cgroup's limit less its usage and the address-space limit
 * (RLIMIT_AS) less the address space in use; `what` ends "...: fewer"
 * messages, e.g. "the memory cgroup's limit of 400 MB leaves 350 MB". */
typedef struct sph_memory_limit {
  double bytes;
  int by_option; /* the limit is max_memory */
  char what[160];
} sph_memory_limit;

void sph_memory_limit_get(double max_memory, sph_memory_limit *lim);

#endif
