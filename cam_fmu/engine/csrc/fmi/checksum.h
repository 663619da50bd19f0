/* A serialized FMU state's checksum: CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, as zlib's crc32)
 * over every byte before it, written as 4 little-endian bytes after them. It catches every single-bit flip
 * and every burst of up to 32 bits; the entries' own checks (ranges, consistency) cannot see a flip that
 * leaves a plausible value. */
#ifndef CAM_CHECKSUM_H
#define CAM_CHECKSUM_H

#include <stddef.h>

#define CHECKSUM_BYTES 4

/* CRC-32 of n bytes. */
unsigned long checksum_crc32(const unsigned char *bytes, size_t n);
/* Write the checksum of bytes[0..n) into bytes[n..n+4). */
void checksum_append(unsigned char *bytes, size_t n);
/* 1 if bytes[n..n+4) holds the checksum of bytes[0..n), else 0. */
int checksum_valid(const unsigned char *bytes, size_t n);

#endif
