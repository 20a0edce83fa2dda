/* zip_normalize <file.zip>: make a zip written by `cmake -E tar --format=zip
 * --mtime=...` depend on its contents alone. libarchive also records each
 * file's access and change times (extra field "UT"), its owner ("ux") and
 * its permission bits as the build left them (umask): those differ between
 * checkouts and users. Rewritten in place, same length, so no offset moves:
 * access and change time = modification time, owner = 0/0, permissions
 * 0644 or 0755 (any execute bit). Data and CRCs are not touched.
 * Exit status 0: done; 1: not a zip this tool understands (left as is). */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LOCAL_SIGNATURE 0x04034b50u
#define CENTRAL_SIGNATURE 0x02014b50u
#define END_SIGNATURE 0x06054b50u
#define EXTENDED_TIMESTAMP 0x5455u /* "UT" */
#define UNIX_OWNER 0x7875u         /* "ux" */
#define MADE_BY_UNIX 3

static unsigned get16(const unsigned char *p) {
    return (unsigned)p[0] | (unsigned)p[1] << 8;
}

static uint32_t get32(const unsigned char *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void put32(unsigned char *p, uint32_t v) {
    for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}

static int fail(const char *path, const char *why) {
    fprintf(stderr, "zip_normalize: %s: %s\n", path, why);
    return 1;
}

/* The extra fields in [p, p + size): times and owner made fixed. */
static int normalize_extra(unsigned char *p, size_t size) {
    size_t at = 0;
    while (at + 4 <= size) {
        const unsigned id = get16(p + at), length = get16(p + at + 2);
        unsigned char *data = p + at + 4;
        if (at + 4 + length > size) return -1;
        if (id == EXTENDED_TIMESTAMP && length >= 5 && (data[0] & 1)) {
            /* flags, then the times the flags name, mtime first */
            const uint32_t mtime = get32(data + 1);
            for (unsigned k = 5; k + 4 <= length; k += 4) put32(data + k, mtime);
        } else if (id == UNIX_OWNER && length >= 3) {
            /* version, uid size, uid, gid size, gid */
            unsigned k = 1;
            for (int field = 0; field < 2 && k < length; field++) {
                const unsigned n = data[k];
                if (k + 1 + n > length) return -1;
                memset(data + k + 1, 0, n);
                k += 1 + n;
            }
        }
        at += 4 + (size_t)length;
    }
    return 0;
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: zip_normalize <file.zip>\n");
        return 2;
    }
    const char *path = argv[1];
    FILE *f = fopen(path, "rb");
    if (!f) return fail(path, "cannot open");
    fseek(f, 0, SEEK_END);
    const long length = ftell(f);
    fseek(f, 0, SEEK_SET);
    if (length < 22) {
        fclose(f);
        return fail(path, "too short for a zip");
    }
    const size_t size = (size_t)length;
    unsigned char *zip = malloc(size);
    if (!zip || fread(zip, 1, size, f) != size) {
        fclose(f);
        free(zip);
        return fail(path, "cannot read");
    }
    fclose(f);

    /* end of central directory: the last signature within 64 KiB + 22 */
    size_t end = size - 22;
    while (end > 0 && get32(zip + end) != END_SIGNATURE && size - end < 65557) end--;
    int status = 0;
    if (get32(zip + end) != END_SIGNATURE) {
        status = fail(path, "no end of central directory");
    }
    const unsigned entries = status ? 0 : get16(zip + end + 10);
    size_t at = status ? 0 : get32(zip + end + 16);
    for (unsigned i = 0; i < entries && !status; i++) {
        unsigned char *c = zip + at;
        if (at + 46 > end || get32(c) != CENTRAL_SIGNATURE) {
            status = fail(path, "broken central directory");
            break;
        }
        const unsigned nameLength = get16(c + 28), extraLength = get16(c + 30), commentLength = get16(c + 32);
        const size_t local = get32(c + 42);
        if (at + 46 + nameLength + extraLength > end || normalize_extra(c + 46 + nameLength, extraLength) != 0) {
            status = fail(path, "broken central extra field");
            break;
        }
        if (c[5] == MADE_BY_UNIX) {
            const uint32_t mode = get32(c + 38) >> 16;
            const uint32_t permissions = (mode & 0111) ? 0755 : 0644;
            put32(c + 38, ((mode & ~07777u) | permissions) << 16 | (get32(c + 38) & 0xFFFF));
        }
        unsigned char *l = zip + local;
        if (local + 30 > size || get32(l) != LOCAL_SIGNATURE) {
            status = fail(path, "broken local header");
            break;
        }
        const unsigned localName = get16(l + 26), localExtra = get16(l + 28);
        if (local + 30 + localName + localExtra > size || normalize_extra(l + 30 + localName, localExtra) != 0) {
            status = fail(path, "broken local extra field");
            break;
        }
        at += 46 + (size_t)nameLength + extraLength + commentLength;
    }
    if (!status) {
        f = fopen(path, "r+b");
        const bool written = f && fwrite(zip, 1, size, f) == size;
        if ((f && fclose(f) != 0) || !written) status = fail(path, "cannot write");
    }
    free(zip);
    return status;
}
