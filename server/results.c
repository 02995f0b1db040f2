/*
 * server/results — the bounded result cache of the GET form of renders (see results.h).
 * Entries sit on one list, most recently used first; the few thousand a cache holds are found
 * by a linear scan under the mutex (microseconds against a render's milliseconds).
 */
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "results.h"

#define SCENE_BUDGET_MIN ((uint64_t)1 << 20)

struct result {
	struct result *prev, *next;
	uint64_t hash;
	char ext[8];
	const char *mime;          /* a static string (api_format_mime) */
	uint8_t *image;            /* NULL: evicted (or never stored) */
	size_t image_len;
	char *warnings;            /* the image's Umbra-Warnings, NULL = none (dropped with it) */
	struct srv_kept_scene scene;   /* empty: not kept */
};

struct srv_results {
	pthread_mutex_t lock;
	struct result *head, *tail;
	uint64_t image_budget, scene_budget;
	uint64_t image_bytes, scene_bytes, images, scenes;
};

struct srv_results *srv_results_create(uint64_t image_bytes)
{
	if (!image_bytes)
		return NULL;
	struct srv_results *r = calloc(1, sizeof *r);
	if (!r)
		return NULL;
	pthread_mutex_init(&r->lock, NULL);
	r->image_budget = image_bytes;
	r->scene_budget = image_bytes / 8 > SCENE_BUDGET_MIN ? image_bytes / 8 : SCENE_BUDGET_MIN;
	return r;
}

void srv_kept_release(struct srv_kept_scene *k)
{
	if (!k)
		return;
	free(k->body);
	for (size_t i = 0; i < k->part_count; i++) {
		free(k->parts[i].name);
		free(k->parts[i].data);
	}
	free(k->parts);
	*k = (struct srv_kept_scene){ 0 };
}

void srv_results_destroy(struct srv_results *r)
{
	if (!r)
		return;
	for (struct result *e = r->head, *next; e; e = next) {
		next = e->next;
		free(e->image);
		free(e->warnings);
		srv_kept_release(&e->scene);
		free(e);
	}
	pthread_mutex_destroy(&r->lock);
	free(r);
}

bool srv_scene_keep(struct srv_kept_scene *k, struct srv_request *req)
{
	size_t bytes = req->body_len;
	for (size_t i = 0; i < req->part_count; i++)
		bytes += req->parts[i].len + strlen(req->parts[i].name);
	if (!req->body || bytes > SRV_SCENE_KEEP_MAX)
		return false;
	*k = (struct srv_kept_scene){ .body = req->body, .body_len = req->body_len, .parts = req->parts,
	                              .part_count = req->part_count, .want = req->want, .bytes = bytes };
	req->body = NULL;
	req->body_len = req->body_cap = 0;
	req->parts = NULL;
	req->part_count = 0;
	return true;
}

void srv_scene_give(struct srv_kept_scene *k, struct srv_request *req)
{
	req->body = k->body;
	req->body_len = k->body_len;
	req->body_cap = k->body_len + 1;
	req->parts = k->parts;
	req->part_count = k->part_count;
	req->want = k->want;
	*k = (struct srv_kept_scene){ 0 };
}

/* A deep copy (body NUL-terminated like a request's). False when out of memory (*out empty). */
static bool scene_copy(const struct srv_kept_scene *k, struct srv_kept_scene *out)
{
	*out = (struct srv_kept_scene){ .want = k->want, .bytes = k->bytes };
	out->body = malloc(k->body_len + 1);
	out->parts = k->part_count ? calloc(k->part_count, sizeof *out->parts) : NULL;
	if (!out->body || (k->part_count && !out->parts))
		goto fail;
	memcpy(out->body, k->body, k->body_len);
	out->body[k->body_len] = 0;
	out->body_len = k->body_len;
	for (size_t i = 0; i < k->part_count; i++, out->part_count++) {
		const struct srv_part *p = &k->parts[i];
		struct srv_part *q = &out->parts[i];
		q->name = strdup(p->name);
		q->data = malloc(p->len + 1);
		if (!q->name || !q->data) {
			out->part_count++;   /* released with the others */
			goto fail;
		}
		memcpy(q->data, p->data, p->len);
		q->data[p->len] = 0;
		q->len = p->len;
		q->cap = p->len + 1;
	}
	return true;
fail:
	srv_kept_release(out);
	return false;
}

static void unlink_entry(struct srv_results *r, struct result *e)
{
	if (e->prev) e->prev->next = e->next; else r->head = e->next;
	if (e->next) e->next->prev = e->prev; else r->tail = e->prev;
	e->prev = e->next = NULL;
}

static void push_front(struct srv_results *r, struct result *e)
{
	e->next = r->head;
	e->prev = NULL;
	if (r->head) r->head->prev = e; else r->tail = e;
	r->head = e;
}

static void drop_image(struct srv_results *r, struct result *e)
{
	if (!e->image)
		return;
	r->image_bytes -= e->image_len;
	r->images--;
	free(e->image);
	free(e->warnings);
	e->image = NULL;
	e->warnings = NULL;
	e->image_len = 0;
}

static void drop_scene(struct srv_results *r, struct result *e)
{
	if (!e->scene.body)
		return;
	r->scene_bytes -= e->scene.bytes;
	r->scenes--;
	srv_kept_release(&e->scene);
}

/* Evicts least recently used images, then scenes, until both are within budget; frees the
 * entries left with neither. */
static void trim(struct srv_results *r)
{
	for (struct result *e = r->tail, *prev; e && (r->image_bytes > r->image_budget || r->scene_bytes > r->scene_budget);
	     e = prev) {
		prev = e->prev;
		if (r->image_bytes > r->image_budget)
			drop_image(r, e);
		if (r->scene_bytes > r->scene_budget)
			drop_scene(r, e);
		if (!e->image && !e->scene.body) {
			unlink_entry(r, e);
			free(e);
		}
	}
}

static struct result *find(struct srv_results *r, uint64_t hash, const char *ext)
{
	for (struct result *e = r->head; e; e = e->next)
		if (e->hash == hash && !strcmp(e->ext, ext))
			return e;
	return NULL;
}

bool srv_results_put(struct srv_results *r, uint64_t hash, const char *ext, const struct srv_result_image *img,
                     struct srv_kept_scene *kept)
{
	if (!r || img->len > r->image_budget || strlen(ext) >= sizeof ((struct result *)0)->ext)
		goto refuse;
	size_t len = img->len;
	uint8_t *copy = malloc(len ? len : 1);
	char *warnings = img->warnings && *img->warnings ? strdup(img->warnings) : NULL;
	if (!copy || (img->warnings && *img->warnings && !warnings)) {
		free(copy);
		free(warnings);
		goto refuse;
	}
	memcpy(copy, img->data, len);
	pthread_mutex_lock(&r->lock);
	struct result *e = find(r, hash, ext);
	if (!e && (e = calloc(1, sizeof *e))) {
		e->hash = hash;
		strcpy(e->ext, ext);
		push_front(r, e);
	}
	if (!e) {
		pthread_mutex_unlock(&r->lock);
		free(copy);
		free(warnings);
		goto refuse;
	}
	drop_image(r, e);
	e->image = copy;
	e->image_len = len;
	e->warnings = warnings;
	e->mime = img->mime;
	r->image_bytes += len;
	r->images++;
	if (kept && kept->body && !e->scene.body) {
		e->scene = *kept;
		*kept = (struct srv_kept_scene){ 0 };
		r->scene_bytes += e->scene.bytes;
		r->scenes++;
	}
	unlink_entry(r, e);
	push_front(r, e);
	trim(r);
	pthread_mutex_unlock(&r->lock);
	srv_kept_release(kept);
	return true;
refuse:
	srv_kept_release(kept);
	return false;
}

/* The entry's image as malloc'd copies; false when out of memory (nothing to free). */
static bool image_copy(const struct result *e, struct srv_result_image *out)
{
	*out = (struct srv_result_image){ .len = e->image_len, .mime = e->mime };
	out->data = malloc(e->image_len ? e->image_len : 1);
	out->warnings = e->warnings ? strdup(e->warnings) : NULL;
	if (!out->data || (e->warnings && !out->warnings)) {
		free(out->data);
		free((char *)out->warnings);
		*out = (struct srv_result_image){ 0 };
		return false;
	}
	memcpy(out->data, e->image, e->image_len);
	return true;
}

enum srv_result_found srv_results_get(struct srv_results *r, uint64_t hash, const char *ext,
                                      struct srv_result_image *img, struct srv_kept_scene *scene)
{
	enum srv_result_found found = SRV_RESULT_NONE;
	if (!r)
		return found;
	pthread_mutex_lock(&r->lock);
	struct result *e = find(r, hash, ext);
	if (e) {
		unlink_entry(r, e);
		push_front(r, e);
		found = e->image ? SRV_RESULT_IMAGE : SRV_RESULT_SCENE;
	}
	if (e && img && e->image) {
		if (!image_copy(e, img))
			found = SRV_RESULT_NONE;
	} else if (e && img && !scene_copy(&e->scene, scene)) {
		found = SRV_RESULT_NONE;
	}
	pthread_mutex_unlock(&r->lock);
	return found;
}

void srv_results_stats(struct srv_results *r, struct srv_results_stats *out)
{
	*out = (struct srv_results_stats){ 0 };
	if (!r)
		return;
	pthread_mutex_lock(&r->lock);
	*out = (struct srv_results_stats){ r->image_bytes, r->scene_bytes, r->images, r->scenes, r->image_budget };
	pthread_mutex_unlock(&r->lock);
}
