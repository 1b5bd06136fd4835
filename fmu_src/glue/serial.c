#include "serial.h"

#include <string.h>

/* n bytes of value, least significant first; and back. */
static void put_le(unsigned char *at, uint64_t value, int n)
{
    int i;
    for (i = 0; i < n; i++)
        at[i] = (unsigned char)(value >> (8 * i));
}

static uint64_t get_le(const unsigned char *at, int n)
{
    uint64_t value = 0;
    int i;
    for (i = 0; i < n; i++)
        value |= (uint64_t)at[i] << (8 * i);
    return value;
}

void serial_put_u32(unsigned char *at, uint32_t value)
{
    put_le(at, value, 4);
}

uint32_t serial_get_u32(const unsigned char *at)
{
    return (uint32_t)get_le(at, 4);
}

void serial_put_u64(unsigned char *at, uint64_t value)
{
    put_le(at, value, 8);
}

uint64_t serial_get_u64(const unsigned char *at)
{
    return get_le(at, 8);
}

void serial_put_double(unsigned char *at, double value)
{
    uint64_t bits;
    memcpy(&bits, &value, sizeof bits);
    serial_put_u64(at, bits);
}

double serial_get_double(const unsigned char *at)
{
    uint64_t bits = serial_get_u64(at);
    double value;
    memcpy(&value, &bits, sizeof value);
    return value;
}

uint32_t serial_crc32(const unsigned char *bytes, size_t n)
{
    uint32_t crc = 0xFFFFFFFFu;
    size_t i;
    int k;
    for (i = 0; i < n; i++) {
        crc ^= bytes[i];
        for (k = 0; k < 8; k++)
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}
