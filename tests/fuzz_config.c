/* libFuzzer target for the service's config file (service/svc_config.c,
 * the parser behind `ringside serve --config`): `make fuzz` builds it,
 * seeds in tests/fuzz/config/.  The input is a config file.  What is
 * refused says so in a "fuzz.conf..." message with a config id; what is
 * accepted dumps (svc_config_dump, the "config file that reproduces it")
 * to a text that parses to a config dumping the same text again, so every
 * value accepted is within its row's bounds and survives a round trip;
 * and svc_config_finish, when it agrees, leaves the size within max_size. */
#define _GNU_SOURCE /* open_memstream */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/util/rs_file.h"
#include "../service/svc_config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char *dump(const svc_config *c, size_t *len)
{
    char *text = NULL;
    FILE *f = open_memstream(&text, len);
    if (!f)
        abort();
    svc_config_dump(c, f);
    fclose(f);
    return text;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    svc_config c;
    rs_err err = {0};
    svc_config_defaults(&c);
    if (!svc_config_parse(&c, "fuzz.conf", (const char *)data, size, &err)) {
        if (strncmp(err.msg, "fuzz.conf:", 10) != 0 ||
            (RS_ERR_MODULE(err.code) != RS_ERR_MOD_SVC_CONFIG && err.code != RS_FILE_ERR_READ))
            abort();
        return 0;
    }
    size_t n1, n2;
    char *one = dump(&c, &n1);
    svc_config again;
    svc_config_defaults(&again);
    if (!svc_config_parse(&again, "dump.conf", one, n1, &err))
        abort(); /* the dump of what was accepted is refused: err.msg says why */
    char *two = dump(&again, &n2);
    if (n1 != n2 || memcmp(one, two, n1) != 0)
        abort();
    free(one);
    free(two);
    if (svc_config_finish(&c, &err) && (c.width > c.max_width || c.height > c.max_height || !c.queue[0] || !c.output[0]))
        abort();
    return 0;
}
