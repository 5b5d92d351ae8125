/* fuzz_spec.c - libFuzzer harness for the job-spec parser and validator: any bytes in,
 * either a valid spec or an error with a JSON pointer and a message out, never a crash,
 * a leak or undefined behaviour. Built by -DGP_FUZZ=ON with clang; in every other build
 * the same function is linked to replay_main.c, and ctest replays the corpus through it. */
#include <stdint.h>
#include <string.h>

#include "grainpack/spec.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* small caps, so that a valid spec found by the fuzzer never asks for much memory */
    gp_spec_limits limits = {.max_disks = 100000, .max_bins = 1000};
    gp_spec spec;
    gp_error err;
    int rc = gp_spec_parse((const char *)data, size, &limits, &spec, &err);
    if (rc == 0) {
        /* a valid spec is complete and in range */
        if (!(spec.domain.width > 0 && spec.domain.height > 0) || !(spec.expected_disks <= 100000))
            __builtin_trap();
        gp_spec_free(&spec);
    } else if (err.code != rc || err.message[0] == '\0' ||
               memchr(err.pointer, '\0', sizeof err.pointer) == NULL) {
        __builtin_trap(); /* every failure explains itself */
    }
    return 0;
}
