/* Checksums with no dependencies, shared by every layer: the frame hash of
 * `render --hashes` and `movie --hashes`, and the CRC that PNG chunks and
 * replay files carry. */
#ifndef RS_HASH_H
#define RS_HASH_H

#include <stddef.h>
#include <stdint.h>

/* 64-bit FNV-1a of n bytes: the frame hash written to --hashes (its value
 * for the same bytes must never change, or every stored hash list breaks). */
uint64_t rs_fnv1a64(const void *data, size_t n);

/* CRC-32 (IEEE 802.3, as PNG and zlib), continued from crc (0 to start). */
uint32_t rs_crc32(uint32_t crc, const void *data, size_t n);

/* A small integer hash of a lattice point (x, y) and a seed: the
 * procedural textures' deterministic noise, with no libc rand() state.
 * Its value for the same inputs must never change: every frame shows
 * textures made from it. */
static inline uint32_t rs_hash_point(uint32_t x, uint32_t y, uint32_t seed)
{
    uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ seed * 0xcb1ab31fu;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return h;
}

#endif
