/* Runs the FMI fuzz harness once on each file named on the command line
 * (the seed corpus and every input that ever crashed it), so that builds
 * without libFuzzer (gcc, the sanitizer build) replay them as regression
 * tests. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int main(int argc, char **argv)
{
    static uint8_t data[1 << 20];
    int i;
    for (i = 1; i < argc; i++) {
        FILE *f = fopen(argv[i], "rb");
        size_t n;
        if (!f) {
            fprintf(stderr, "fuzz_replay: cannot read %s\n", argv[i]);
            return 1;
        }
        n = fread(data, 1, sizeof data, f);
        fclose(f);
        LLVMFuzzerTestOneInput(data, n);
    }
    printf("fuzz_replay: %d passed, 0 failed\n", argc - 1);
    return 0;
}
