/*
 * api/sandbox — model import and image decoding of untrusted bytes in helper processes.
 *
 * Why: Assimp, libpng and libjpeg are big parsers of attacker-controlled bytes. A malformed PLY
 * of 500 bytes crashed the whole daemon (SIGSEGV inside Assimp), another looped for ever while
 * holding the import lock. Parsing happens in a child process instead, under limits the daemon
 * chose; what can go wrong there (a crash, a loop, a runaway allocation) ends that child and
 * becomes a 400/422 for that one object.
 *
 * Design (a "fork server"):
 *   - `build/umbra-import` (api/helper/umbra_import.c) is a small single-threaded executable
 *     started once per process with posix_spawn (found next to the running executable through
 *     /proc/self/exe, or its parent directory for the test binaries in build/tests, or env UMBRA_IMPORT_HELPER).
 *     Forking the daemon itself is not an option: it is multithreaded and holds a Vulkan
 *     device; a fork of it would copy locks held by other threads and driver state. Spawning a
 *     fresh executable per import would cost a dynamic link of Assimp (~10 ms) each time; the
 *     fork server pays that once and forks a clean, single-threaded copy of itself per job.
 *   - One job = one child. The daemon makes a socketpair (data), a pipe (status) and a memfd
 *     (the reply), sends the request and the three fds over the control socket (SOCK_SEQPACKET:
 *     each request is one atomic message, so threads send concurrently without a lock), and
 *     writes the input into the data socket. The child writes its reply into the memfd through
 *     a shared mapping and its length on the data socket. Once the child has exited, the daemon
 *     shrinks the memfd to that length, seals it (no write, grow or shrink, by anyone: the seal
 *     on writing is refused while any writable mapping exists), maps it read-only and decodes
 *     it there: a model's arrays stay in that mapping, owned by its arena, with no copy (a
 *     1M-triangle model's 84 MB went through the socket and two copies before). Nothing global
 *     is held meanwhile: imports of different requests run in parallel, each in its own child.
 *   - The child, before it reads a byte: closes every fd but its data socket and reply file,
 *     sets RLIMIT_CPU (the timeout, rounded up to seconds), RLIMIT_AS (the memory limit: the
 *     reply's mapping counts in it), RLIMIT_FSIZE/NOFILE/CORE/NPROC,
 *     PR_SET_NO_NEW_PRIVS and a seccomp filter (libseccomp) that allows only what parsing needs
 *     (read/write on its fds, memory management without PROT_EXEC, futex, exit, signals to
 *     itself). No open, no socket, no exec: the child can touch no file beyond its fds.
 *   - The fork server kills a child at its wall-clock timeout (it is the child's parent, so
 *     the pid cannot have been reused) and writes how the child ended into the status pipe.
 *   - The daemon validates everything it reads back (api/model_wire.h) as untrusted.
 *   - A model that refers to other files (a .gltf's .bin and images, an .obj's .mtl and
 *     textures) gets them in its input, read by the daemon (api/model_refs.h): the model's
 *     bytes, then name + bytes per file (api_sbx_bundle_encode); the child's Assimp file
 *     system serves exactly those names from memory.
 *
 * Outcomes: API_OK; else *status says 400 (the bytes are bad: the parser refused them, crashed,
 * or was stopped by the filter), 422 (over the time or memory limit) or 500 (the helper could
 * not be started), with a sentence in err that names no member (the caller adds the pointer).
 * Each job is counted by how it ended, with its time and the fork server's restarts, for
 * /metrics: api/sandbox_stats.h.
 *
 * Threading: every function is thread-safe. The fork server is started on first use and
 * restarted when it died; a mutex guards only that start, never a job.
 */
#ifndef UMBRA_API_SANDBOX_H
#define UMBRA_API_SANDBOX_H

#include <stddef.h>
#include <stdint.h>
#include "api.h"
#include "arena.h"
#include "model.h"

/* Imports a model (format not SNIFF) under the limits' import_timeout_ms / import_memory
 * (NULL = defaults) into *out, its arrays in `arena`; *bytes = what the arena holds for it. */
enum api_result api_sandbox_import_model(const uint8_t *data, size_t len, enum api_model_format format,
                                         const struct api_limits *lim, struct api_arena *arena,
                                         struct api_model *out, size_t *bytes, int *status, char *err,
                                         size_t errsize);
/* The same for a model with the files it refers to: `bundle` (bundle_len bytes) is the model's
 * len bytes followed by nfiles files, as api_sbx_bundle_encode() lays them out. */
enum api_result api_sandbox_import_bundle(const uint8_t *bundle, size_t bundle_len, size_t len, size_t nfiles,
                                          enum api_model_format format, const struct api_limits *lim,
                                          struct api_arena *arena, struct api_model *out, size_t *bytes,
                                          int *status, char *err, size_t errsize);
/* The levels of detail for images of `side` of m's meshes that want them (api/model_lod.h),
 * built in a child under lim's import limits like an import, validated (api_wire_decode_levels)
 * into arena: out[i] for mesh i (count 0 for the others); *bytes = what the arena holds. */
enum api_result api_sandbox_build_levels(const struct api_model *m, uint32_t side, const struct api_limits *lim,
                                         struct api_arena *arena, struct api_mesh_levels *out, size_t *bytes,
                                         int *status, char *err, size_t errsize);
/* Decodes a PNG or JPEG (at most max_pixels) into malloc'd RGBA8 (*rgba, you free it). */
enum api_result api_sandbox_decode_image(const uint8_t *data, size_t len, uint64_t max_pixels,
                                         const struct api_limits *lim, uint8_t **rgba, uint32_t *w, uint32_t *h,
                                         int *status, char *err, size_t errsize);
/* Path of the helper executable that will be (or was) started. */
const char *api_sandbox_helper_path(void);

/* ---- protocol between api/sandbox.c and api/sandbox_child.c (private) ---- */

/* Sanitizer builds (make test-asan, fuzzing) reserve terabytes of address space and make
 * system calls of their own: they get no RLIMIT_AS and a filter that fails calls instead of
 * killing (api/sandbox_child.c). */
#if defined(__SANITIZE_ADDRESS__)
#define API_SBX_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define API_SBX_SANITIZED 1
#endif
#endif
#ifndef API_SBX_SANITIZED
#define API_SBX_SANITIZED 0
#endif

#define API_SBX_MAGIC 0x756d6272u      /* "umbr" */
#define API_SBX_CTL_FD 3               /* the fork server's control socket */
#define API_SBX_DATA_FD 3              /* a child's data socket */
#define API_SBX_REPLY_FD 4             /* a child's reply file (a memfd the daemon made) */
#define API_SBX_MAX_CHILDREN 1024

/* Sent over the control socket with SCM_RIGHTS {data socket, status pipe's write end, reply
 * memfd}. */
struct api_sbx_request {
	uint32_t magic;
	uint32_t kind;          /* enum api_wire_kind */
	uint32_t format;        /* model: enum api_model_format */
	uint32_t timeout_ms;    /* wall clock, killed by the fork server; CPU limit derived */
	uint64_t memory;        /* RLIMIT_AS bytes */
	uint64_t max_pixels;    /* per image / texture */
	uint64_t input_len;     /* bytes that follow on the data socket */
	uint64_t model_len;     /* model: the model file's bytes at the start of the input ... */
	uint32_t file_count;    /* ... followed by this many files (api_sbx_bundle_encode) */
	uint32_t output_side;   /* model: api_limits.output_side (api_model_finish_import) */
	uint32_t threads;       /* the import's threads, the caller's included (0: 1; api/workers.h) */
	uint64_t reply_size;    /* the reply file's size: no reply may be longer */
};

/* A model's input with the files it refers to: the model's bytes, then per file
 * {uint32 name_len (with its NUL), uint64 data_len, name, NUL, data}, host byte order (both
 * ends run on one machine). A file whose bytes are an earlier file's (the same data pointer and
 * length: two spellings of one name) has data_len API_SBX_ALIAS | that file's index, no data. Encode: malloc'd, NULL when out of memory or too large. Decode (the
 * child): files[] point into `in`; -1 when the layout is inconsistent. */
#define API_SBX_ALIAS (1ull << 63)
uint8_t *api_sbx_bundle_encode(const uint8_t *model, size_t len, const struct api_model_file *files, size_t n,
                               size_t *out_len);
int api_sbx_bundle_decode(const uint8_t *in, size_t len, size_t model_len, uint32_t count,
                          struct api_model_file *files);

enum api_sbx_how { API_SBX_EXITED = 1, API_SBX_SIGNALED, API_SBX_TIMED_OUT, API_SBX_REFUSED };
/* Child exit codes besides 0. */
enum { API_SBX_EXIT_OOM = 3, API_SBX_EXIT_SETUP = 4, API_SBX_EXIT_IO = 5 };

/* Written by the fork server into the status pipe once the child is reaped. */
struct api_sbx_status {
	uint32_t magic;
	uint32_t how;           /* enum api_sbx_how */
	int32_t code;           /* exit code or signal */
	uint32_t reserved;
};

/* Sends rq with its fds (data socket, status pipe's write end, reply memfd) to the fork server,
 * starting it first, or again once when it is gone (api/sandbox_server.c). 0, or -1 with err. */
int api_sbx_send(const struct api_sbx_request *rq, int data_fd, int status_fd, int reply_fd, char *err,
                 size_t errsize);

/* The helper's environment: env with glibc's malloc tuned for a process that writes its memory
 * once, fresh from the kernel (GLIBC_TUNABLES gets API_SBX_TUNABLES appended, or is added;
 * glibc 2.35+, a no-op where the kernel's THP is off):
 * - glibc.malloc.hugetlb=1: madvise(MADV_HUGEPAGE) on the heap and on big blocks. With 4 KiB
 *   pages a 1M-triangle STL took a page fault every 4 KiB, a fifth of its time on a
 *   virtualised machine, and its whole import took twice as long.
 * - glibc.malloc.mmap_threshold=32 MiB (glibc's largest): blocks up to that size come from the
 *   heap, which grows in huge pages, instead of a mapping of their own each, 4 KiB pages but
 *   for the 2 MiB-aligned middle of those over 2 MiB. A 100k-triangle import touched ~4,800
 *   pages (70 ms of its CPU in a fresh process), ~650 with this (22 ms).
 * Returns a malloc'd array (the variables point into env, but GLIBC_TUNABLES into *own,
 * malloc'd too), or NULL (and *own NULL) when out of memory. */
#define API_SBX_TUNABLES "glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=33554432"
char **api_sbx_helper_env(char *const *env, char **own);

/* The helper's main (api/helper/umbra_import.c calls it): `umbra-import --fork-server`. */
int api_sandbox_helper_main(int argc, char **argv);

#endif
