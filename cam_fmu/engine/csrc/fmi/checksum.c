/* CRC-32 of a serialized FMU state (checksum.h), bit by bit: no table, no globals. */
#include "checksum.h"

unsigned long checksum_crc32(const unsigned char *bytes, size_t n)
{
    unsigned long crc = 0xffffffffUL;
    size_t k;
    int bit;
    for (k = 0; k < n; k++) {
        crc ^= bytes[k];
        for (bit = 0; bit < 8; bit++)
            crc = (crc >> 1) ^ (0xedb88320UL & (0UL - (crc & 1UL)));
    }
    return (crc ^ 0xffffffffUL) & 0xffffffffUL;
}

void checksum_append(unsigned char *bytes, size_t n)
{
    unsigned long crc = checksum_crc32(bytes, n);
    int k;
    for (k = 0; k < CHECKSUM_BYTES; k++)
        bytes[n + (size_t)k] = (unsigned char)((crc >> (8 * k)) & 0xffUL);
}

int checksum_valid(const unsigned char *bytes, size_t n)
{
    unsigned long crc = checksum_crc32(bytes, n), stored = 0;
    int k;
    for (k = CHECKSUM_BYTES - 1; k >= 0; k--)
        stored = (stored << 8) | bytes[n + (size_t)k];
    return stored == crc;
}
