/*
 * umbra-import — the sandboxed importer's executable (see api/sandbox.h): started by umbrad
 * and umbra-render as `umbra-import --fork-server` with its control socket on fd 3; it forks
 * one restricted child per model import or image decode. Not meant to be run by hand.
 *
 * The allocation wrappers below exist only in this executable (never in libapi.a, where they
 * would replace the daemon's malloc): a child that crashes right after an allocation failed
 * ran into its memory limit (RLIMIT_AS), which is a 422, not a broken file (400). They forward
 * to glibc's allocator and only note a failure. Sanitizer builds keep their own allocator and
 * have no memory limit (see api/sandbox_child.c).
 */
#include <signal.h>
#include <stddef.h>
#include "sandbox.h"

volatile sig_atomic_t api_sbx_alloc_failed;

#if !API_SBX_SANITIZED
extern void *__libc_malloc(size_t n);
extern void *__libc_calloc(size_t n, size_t size);
extern void *__libc_realloc(void *p, size_t n);

void *malloc(size_t n)
{
	void *p = __libc_malloc(n);
	if (!p && n) api_sbx_alloc_failed = 1;
	return p;
}

void *calloc(size_t n, size_t size)
{
	void *p = __libc_calloc(n, size);
	if (!p && n && size) api_sbx_alloc_failed = 1;
	return p;
}

void *realloc(void *old, size_t n)
{
	void *p = __libc_realloc(old, n);
	if (!p && n) api_sbx_alloc_failed = 1;
	return p;
}
#endif

int main(int argc, char **argv)
{
	return api_sandbox_helper_main(argc, argv);
}
