/* Compiled, not run, by every build, the Windows part's too: on 64-bit
 * Windows long is 32 bits (LLP64), and the counters the FMU state carries
 * must be 64 bits there too, or a state serialized on Linux would not restore
 * on Windows and a long soak would overflow. A wrong width is a compile error
 * here. */
#include "contact.h"

#define SIXTY_FOUR_BITS(field) typedef char field##_is_64_bits[sizeof(((contact_state *)0)->field) == 8 ? 1 : -1];
#define ANY_WIDTH(field)

CONTACT_STATE_FIELDS(ANY_WIDTH, SIXTY_FOUR_BITS, ANY_WIDTH)
