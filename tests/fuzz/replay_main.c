/* Runs a libFuzzer target's LLVMFuzzerTestOneInput over the files named on
 * the command line in a build without libFuzzer (the regression inputs of
 * tests/fuzz/regressions_vtk/ and regressions_checkpoint/ in every build,
 * ctest -R fuzz_regressions): a crash fails the test; prints how many
 * inputs ran. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int main(int argc, char **argv) {
  LLVMFuzzerInitialize(&argc, &argv);
  int n = 0;
  for (int i = 1; i < argc; ++i) {
    FILE *f = fopen(argv[i], "rb");
    if (!f) {
      perror(argv[i]);
      return 2;
    }
    uint8_t *buf = NULL;
    size_t len = 0, cap = 0, got;
    do {
      if (len == cap) {
        cap = cap ? 2 * cap : 65536;
        uint8_t *grown = realloc(buf, cap);
        if (!grown)
          return 2;
        buf = grown;
      }
      got = fread(buf + len, 1, cap - len, f);
      len += got;
    } while (got > 0);
    fclose(f);
    LLVMFuzzerTestOneInput(buf, len);
    free(buf);
    ++n;
  }
  printf("%d inputs replayed\n", n);
  return n > 0 ? 0 : 1;
}
