/* Runs the FMI fuzz harness once on each file named on the command line
 * (the seed corpus and every input that ever crashed it), so that builds
 * without libFuzzer (gcc, the sanitizer build) replay them as regression
 * tests. With -timeout=S first (libFuzzer's option, in CPU seconds here),
 * an input that takes longer fails the run: the harness bounds each input's
 * work (fuzz_program.h), and a slow input would slow the fuzzer down. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int main(int argc, char **argv)
{
    static uint8_t data[1 << 20];
    const int first = argc > 1 && strncmp(argv[1], "-timeout=", 9) == 0 ? 2 : 1;
    const double limit = first == 2 ? atof(argv[1] + 9) : 0.0;
    int i;
    for (i = first; i < argc; i++) {
        FILE *f = fopen(argv[i], "rb");
        size_t n;
        clock_t start;
        double seconds;
        if (!f) {
            fprintf(stderr, "fuzz_replay: cannot read %s\n", argv[i]);
            return 1;
        }
        n = fread(data, 1, sizeof data, f);
        fclose(f);
        start = clock();
        LLVMFuzzerTestOneInput(data, n);
        seconds = (double)(clock() - start) / CLOCKS_PER_SEC;
        if (limit > 0.0 && seconds > limit) {
            fprintf(stderr, "fuzz_replay: %s took %.3g s of CPU, more than -timeout=%g\n", argv[i], seconds, limit);
            return 1;
        }
    }
    printf("fuzz_replay: %d passed, 0 failed\n", argc - first);
    return 0;
}
