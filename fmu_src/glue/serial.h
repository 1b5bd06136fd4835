/* Bytes in a fixed, platform-independent layout: little-endian integers and
 * IEEE-754 doubles bit for bit, and a CRC-32 to detect damage. For the FMU
 * state, which must restore exactly in another process or on another
 * machine; it knows nothing of what the bytes mean. */
#ifndef FRACCONTACT_SERIAL_H
#define FRACCONTACT_SERIAL_H

#include <stddef.h>
#include <stdint.h>

void serial_put_u32(unsigned char *at, uint32_t value);
uint32_t serial_get_u32(const unsigned char *at);
void serial_put_u64(unsigned char *at, uint64_t value);
uint64_t serial_get_u64(const unsigned char *at);
void serial_put_double(unsigned char *at, double value);  /* 8 bytes */
double serial_get_double(const unsigned char *at);

/* CRC-32 (IEEE 802.3, as zlib's crc32) of n bytes. */
uint32_t serial_crc32(const unsigned char *bytes, size_t n);

#endif
