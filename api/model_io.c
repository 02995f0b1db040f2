/*
 * api/model_io.c — an aiFileIO that serves one buffer and nothing else (see model_io.h): the
 * model's bytes under its own name, and the files it refers to under the names the model
 * writes; anything else, and any write, fails to open.
 */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "model_io.h"

/* Compares a name Assimp asks for with a file's name as the model wrote it: "\\" as "/", no
 * leading "./", %XX decoded (glTF URIs), so "./a%20b.bin" finds "a b.bin". */
static void name_norm(const char *in, char *out, size_t n)
{
	size_t k = 0;
	while (in[0] == '.' && (in[1] == '/' || in[1] == '\\')) in += 2;
	for (const char *p = in; *p && k + 1 < n; p++) {
		unsigned v;
		if (p[0] == '%' && isxdigit((unsigned char)p[1]) && isxdigit((unsigned char)p[2]) &&
		    sscanf(p + 1, "%2x", &v) == 1) {
			out[k++] = (char)v;
			p += 2;
		} else {
			out[k++] = *p == '\\' ? '/' : *p;
		}
	}
	out[k] = 0;
}

long api_model_file_index(const struct api_model_file *files, size_t n, const char *name)
{
	char a[1024], b[1024];
	name_norm(name, a, sizeof a);
	for (size_t i = 0; i < n; i++) {
		name_norm(files[i].name, b, sizeof b);
		if (!strcmp(a, b)) return (long)i;
	}
	return -1;
}

struct mem_file {
	struct aiFile f;
	const uint8_t *data;
	size_t len, pos;
};

static size_t mem_read(struct aiFile *f, char *buf, size_t size, size_t count)
{
	struct mem_file *m = (struct mem_file *)f->UserData;
	if (!size || !count) return 0;
	size_t avail = m->len - m->pos, want = count;
	if (want > avail / size) want = avail / size;
	memcpy(buf, m->data + m->pos, want * size);
	m->pos += want * size;
	return want;
}

static size_t mem_write(struct aiFile *f, const char *buf, size_t size, size_t count)
{
	(void)f, (void)buf, (void)size, (void)count;
	return 0;
}

static size_t mem_tell(struct aiFile *f)
{
	return ((struct mem_file *)f->UserData)->pos;
}

static size_t mem_size(struct aiFile *f)
{
	return ((struct mem_file *)f->UserData)->len;
}

static void mem_flush(struct aiFile *f)
{
	(void)f;
}

static enum aiReturn mem_seek(struct aiFile *f, size_t off, enum aiOrigin origin)
{
	struct mem_file *m = (struct mem_file *)f->UserData;
	size_t base = origin == aiOrigin_SET ? 0 : origin == aiOrigin_CUR ? m->pos : m->len;
	if (off > m->len - base) return aiReturn_FAILURE;
	m->pos = base + off;
	return aiReturn_SUCCESS;
}

static struct aiFile *mem_open(struct aiFileIO *io, const char *name, const char *mode)
{
	struct api_mem_io *mi = (struct api_mem_io *)io->UserData;
	/* Only the model itself and the files it refers to, read-only; Assimp may prefix a
	 * directory ("./"). */
	if (mode && strchr(mode, 'w')) return NULL;
	const char *base = strrchr(name, '/');
	base = base ? base + 1 : name;
	long fi = strcmp(base, mi->name) ? api_model_file_index(mi->files, mi->nfiles, name) : -2;
	if (fi == -1) return NULL;
	struct mem_file *m = calloc(1, sizeof *m);
	if (!m) return NULL;
	m->data = fi >= 0 ? mi->files[fi].data : mi->data;
	m->len = fi >= 0 ? mi->files[fi].len : mi->len;
	m->f.ReadProc = mem_read;
	m->f.WriteProc = mem_write;
	m->f.TellProc = mem_tell;
	m->f.FileSizeProc = mem_size;
	m->f.SeekProc = mem_seek;
	m->f.FlushProc = mem_flush;
	m->f.UserData = (aiUserData)m;
	return &m->f;
}

static void mem_close(struct aiFileIO *io, struct aiFile *f)
{
	(void)io;
	if (f) free(f->UserData);
}

void api_mem_io_init(struct api_mem_io *mi, struct aiFileIO *io)
{
	*io = (struct aiFileIO){.OpenProc = mem_open, .CloseProc = mem_close, .UserData = (aiUserData)mi};
}
