/* Private to r_ibl.c (environment, prefilter) and r_ibl_cache.c. */
#ifndef R_IBL_LOCAL_H
#define R_IBL_LOCAL_H

#include "r_ibl.h"

/* p = in with zero fields at their defaults (in NULL: all defaults), checked. */
bool r_ibl_resolve_params(const r_ibl_params *in, r_ibl_params *p, rs_err *err);
/* Every map of out->size[], zeroed. */
bool r_ibl_alloc_maps(r_ibl *out, rs_err *err);

/* A hit fills out's maps and key_dir (out->size already set).  A missing
 * file is a quiet miss; a corrupt one is reported on stderr, one line,
 * and is a miss too. */
bool r_ibl_cache_read(const char *path, const r_ibl_params *p, uint64_t hash, r_ibl *out);
/* Writes atomically (mkdir -p first); a failure is only a warning on stderr. */
void r_ibl_cache_write(const char *path, const r_ibl_params *p, const r_ibl *ibl);

#endif
