/* libFuzzer target for the raw request check (service/svc_wire.c):
 * `make fuzz` builds it, `make fuzz-run-wire FUZZ_SECONDS=600` runs it on
 * tests/fuzz/wire/ as seeds.  The first byte of an input picks how the rest
 * is cut into pieces; the verdict, status and reason, must be the one the
 * whole input gets, as a connection's bytes arrive in any pieces. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "../service/svc_wire.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    size_t piece = 1 + data[0] % 13;
    uint64_t max = data[0] & 0x80 ? 0 : 1u << (data[0] & 31);
    data++, size--;
    svc_wire whole, cut;
    svc_wire_init(&whole, max);
    svc_wire_init(&cut, max);
    int a = svc_wire_feed(&whole, data, size), b = 0;
    for (size_t i = 0; i < size && !b; i += piece)
        b = svc_wire_feed(&cut, data + i, size - i < piece ? size - i : piece);
    if (a != b || strcmp(whole.why, cut.why) || (a && a != 400 && a != 413 && a != 501 && a != 505) ||
        !a != !whole.why[0])
        abort();
    return 0;
}
