/*
 * api/asset — reading files under the asset root (see asset.h). Moved out of
 * api/scene_parse.c, which used realpath() on the root and on the file, compared the two
 * strings, then opened the resolved name: correct, but a symbolic link swapped between the
 * check and the open was followed. openat2(RESOLVE_BENEATH) makes the kernel hold the rule
 * during the open itself; the realpath() comparison remains only for kernels without it.
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <linux/openat2.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>
#include "asset.h"
#include "errmsg.h"
#include "umbra/rnd_math.h"

enum api_result api_asset_check_path(const char *s, char *err, size_t errsize)
{
	bool bad = !s || !s[0] || s[0] == '/' || strchr(s, ':') || strchr(s, '\\');
	/* No ".." segment anywhere: a path never climbs, so it never escapes the root by name. */
	for (const char *q = s; !bad && *q; q = strchr(q, '/') ? strchr(q, '/') + 1 : q + strlen(q))
		if (q[0] == '.' && q[1] == '.' && (q[2] == '/' || q[2] == 0)) bad = true;
	if (bad)
		return api_err_set(err, errsize, "path must be a relative path inside the asset root (no leading \"/\", "
		                   "no \"..\")");
	return API_OK;
}

enum api_result api_asset_resolve(const char *base, const char *ref, char *out, size_t outsize, char *err,
                                  size_t errsize)
{
	if (!ref || !ref[0]) return api_err_set(err, errsize, "an empty file reference");
	if (ref[0] == '/' || ref[0] == '\\' || strchr(ref, ':'))
		return api_err_set(err, errsize, "\"%.128s\" is not a relative reference (no leading \"/\", no scheme or "
		                   "drive)", ref);
	/* The directory of base, then ref, segment by segment into out. */
	char buf[PATH_MAX];
	const char *slash = base ? strrchr(base, '/') : NULL;
	size_t dlen = slash ? (size_t)(slash - base) + 1 : 0;
	if (dlen + strlen(ref) + 1 > sizeof buf || outsize < 2) return api_err_set(err, errsize, "reference too long");
	memcpy(buf, base, dlen);
	strcpy(buf + dlen, ref);
	for (char *p = buf; *p; p++)
		if (*p == '\\') *p = '/';
	size_t n = 0;
	out[0] = 0;
	for (char *seg = buf; seg && *seg;) {
		char *next = strchr(seg, '/');
		if (next) *next++ = 0;
		if (!strcmp(seg, "..")) {
			if (!n)
				return api_err_set(err, errsize, "\"%.128s\" leaves the asset root (\"..\" above it)", ref);
			while (n && out[n - 1] != '/') n--;          /* drop the last segment ... */
			if (n) n--;                                  /* ... and its slash */
			out[n] = 0;
		} else if (seg[0] && strcmp(seg, ".")) {
			size_t sl = strlen(seg);
			if (n + (n ? 1 : 0) + sl + 1 > outsize) return api_err_set(err, errsize, "reference too long");
			if (n) out[n++] = '/';
			memcpy(out + n, seg, sl + 1);
			n += sl;
		}
		seg = next;
	}
	if (!n) return api_err_set(err, errsize, "\"%.128s\" names a directory, not a file", ref);
	return API_OK;
}

/* openat2 relative to the root's descriptor, the kernel refusing any step outside it.
 * Returns the fd, -1 with errno (EXDEV: it would leave the root), or -2 when the system has
 * no openat2 (the caller falls back). */
static int open_beneath(int dirfd, const char *path)
{
#ifdef SYS_openat2
	struct open_how how = {
		.flags = O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY,
		.resolve = RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS,
	};
	long fd = syscall(SYS_openat2, dirfd, path, &how, sizeof how);
	if (fd >= 0) return (int)fd;
	/* ENOSYS: an old kernel; EPERM: a seccomp profile (some container runtimes) refusing it. */
	if (errno == ENOSYS || errno == EPERM) return -2;
	return -1;
#else
	(void)dirfd, (void)path;
	return -2;
#endif
}

/* The fallback: resolve both names and compare. O_NONBLOCK so that a FIFO does not wait. */
static int open_realpath(const char *rroot, const char *path, char *err, size_t errsize)
{
	char full[PATH_MAX], real[PATH_MAX];
	if ((size_t)snprintf(full, sizeof full, "%s/%s", rroot, path) >= sizeof full)
		return api_err_set(err, errsize, "path is too long"), -1;
	if (!realpath(full, real))
		return api_err_set(err, errsize, "path \"%.128s\" cannot be opened: %s", path, strerror(errno)), -1;
	size_t n = strlen(rroot);
	bool inside = !strcmp(rroot, "/") || (!strncmp(real, rroot, n) && real[n] == '/');
	if (!inside)
		return api_err_set(err, errsize, "path \"%.128s\" leaves the asset root (through a symbolic link)", path), -1;
	int fd = open(real, O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
	if (fd < 0) return api_err_set(err, errsize, "path \"%.128s\" cannot be opened: %s", path, strerror(errno)), -1;
	return fd;
}

static int open_asset(const char *root, const char *path, int *status, char *err, size_t errsize)
{
	*status = 400;
	if (!root || !root[0])
		return api_err_set(err, errsize, "path cannot be used: no asset root configured on this server"), -1;
	int dirfd = open(root, O_PATH | O_DIRECTORY | O_CLOEXEC);
	if (dirfd < 0) {
		*status = 500;
		return api_err_set(err, errsize, "the asset root cannot be opened: %s", strerror(errno)), -1;
	}
	int fd = open_beneath(dirfd, path);
	int e = errno;
	close(dirfd);
	if (fd >= 0) return fd;
	if (fd == -1) {
		if (e == EXDEV)
			return api_err_set(err, errsize, "path \"%.128s\" leaves the asset root (through a symbolic link)",
			                   path), -1;
		return api_err_set(err, errsize, "path \"%.128s\" cannot be opened: %s", path, strerror(e)), -1;
	}
	char rroot[PATH_MAX];
	if (!realpath(root, rroot)) {
		*status = 500;
		return api_err_set(err, errsize, "the asset root cannot be resolved: %s", strerror(errno)), -1;
	}
	return open_realpath(rroot, path, err, errsize);
}

static int64_t now_ns(void)
{
	struct timespec t;
	clock_gettime(CLOCK_REALTIME, &t);
	return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}

static void stamp_of(const struct stat *st, int64_t seen, struct api_asset_stamp *out)
{
	*out = (struct api_asset_stamp){(uint64_t)st->st_dev, (uint64_t)st->st_ino, (uint64_t)st->st_size,
	                                (int64_t)st->st_mtim.tv_sec * 1000000000 + st->st_mtim.tv_nsec,
	                                (int64_t)st->st_ctim.tv_sec * 1000000000 + st->st_ctim.tv_nsec, seen};
}

bool api_asset_stamp_settled(const struct api_asset_stamp *s)
{
	int64_t last = s->mtime_ns > s->ctime_ns ? s->mtime_ns : s->ctime_ns;
	bool coarse = s->mtime_ns % 1000000000 == 0 && s->ctime_ns % 1000000000 == 0;
	return s->seen_ns - last > (coarse ? API_ASSET_SETTLE_COARSE_NS : API_ASSET_SETTLE_NS);
}

bool api_asset_stamp_equal(const struct api_asset_stamp *a, const struct api_asset_stamp *b)
{
	return a->dev == b->dev && a->ino == b->ino && a->size == b->size && a->mtime_ns == b->mtime_ns &&
	       a->ctime_ns == b->ctime_ns;
}

/* fstat of an opened asset, refused as api_asset_read() refuses it. */
static enum api_result check_file(int fd, const char *path, struct stat *st, char *err, size_t errsize)
{
	if (fstat(fd, st) < 0 || !S_ISREG(st->st_mode))
		return api_err_set(err, errsize, "path \"%.128s\" is not a regular file", path);
	if (!st->st_size) return api_err_set(err, errsize, "path \"%.128s\" is an empty file (0 bytes)", path);
	if ((uint64_t)st->st_size > API_ASSET_MAX_FILE)
		return api_err_set(err, errsize, "path \"%.128s\" is %llu bytes, larger than the limit of %llu bytes (1 GiB) "
		                   "for one file", path, (unsigned long long)st->st_size,
		                   (unsigned long long)API_ASSET_MAX_FILE);
	return API_OK;
}

enum api_result api_asset_stat(const char *root, const char *path, struct api_asset_stamp *out, int *status,
                               char *err, size_t errsize)
{
	int fd = open_asset(root, path, status, err, errsize);
	if (fd < 0) return API_ERR;
	*status = 400;
	struct stat st;
	int64_t seen = now_ns();
	enum api_result rc = check_file(fd, path, &st, err, errsize);
	close(fd);
	if (rc != API_OK) return rc;
	stamp_of(&st, seen, out);
	*status = 0;
	return API_OK;
}

enum api_result api_asset_read_stamped(const char *root, const char *path, uint8_t **out, size_t *len,
                                       struct api_asset_stamp *stamp, int *status, char *err, size_t errsize)
{
	*out = NULL;
	*len = 0;
	int fd = open_asset(root, path, status, err, errsize);
	if (fd < 0) return API_ERR;
	*status = 400;
	struct stat st;
	uint8_t *buf = NULL;
	int64_t seen = now_ns();
	enum api_result rc = check_file(fd, path, &st, err, errsize);
	if (rc != API_OK) {
	} else if (!(buf = malloc((size_t)st.st_size))) {
		rc = api_err_set(err, errsize, "path \"%.128s\" is too large to read (out of memory)", path);
	} else {
		api_mem_huge(buf, (size_t)st.st_size);
		size_t got = 0;
		while (got < (size_t)st.st_size) {
			ssize_t r = read(fd, buf + got, (size_t)st.st_size - got);
			if (r < 0 && errno == EINTR) continue;
			if (r <= 0) break;
			got += (size_t)r;
		}
		if (got != (size_t)st.st_size) {
			free(buf);
			buf = NULL;
			rc = api_err_set(err, errsize, "path \"%.128s\" could not be read", path);
		}
	}
	close(fd);
	if (rc != API_OK) return rc;
	if (stamp) stamp_of(&st, seen, stamp);
	*status = 0;
	*out = buf;
	*len = (size_t)st.st_size;
	return API_OK;
}

enum api_result api_asset_read(const char *root, const char *path, uint8_t **out, size_t *len, int *status,
                               char *err, size_t errsize)
{
	return api_asset_read_stamped(root, path, out, len, NULL, status, err, errsize);
}

void api_asset_hash(uint64_t *h, const char *name, const uint8_t *data, size_t len)
{
	/* The name as a byte stream, then the bytes a word at a time. */
	uint64_t x = *h ? *h : RND_FNV_SEED;
	if (name) x = rnd_fnv1a(x, name, strlen(name));
	*h = rnd_hash(x, data, len);
}
