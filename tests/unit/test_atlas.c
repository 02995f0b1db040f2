/* tests — renderer/atlas.c (buddy-quadtree shadow-atlas tile allocator) against a reference
 * occupancy grid kept at min_tile granularity. */
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "test.h"
#include "atlas.h"

/* ---- reference model --------------------------------------------------------------------- */

/* One cell per min_tile x min_tile square; 0 = free, otherwise the id of the live tile. */
struct grid {
	uint32_t size, min_tile, cells; /* cells per side */
	uint32_t *owner;
};

static bool grid_init(struct grid *g, uint32_t size, uint32_t min_tile)
{
	g->size = size;
	g->min_tile = min_tile;
	g->cells = size / min_tile;
	g->owner = calloc((size_t)g->cells * g->cells, sizeof *g->owner);
	return g->owner != NULL;
}

static void grid_release(struct grid *g) { free(g->owner); g->owner = NULL; }

/* The tile is aligned, inside the atlas and of a legal size. */
static bool tile_well_formed(const struct rnd_atlas *a, const struct rnd_tile *t, uint32_t want)
{
	return t->size == want && t->size >= a->min_tile && t->size <= a->size && t->x % t->size == 0 &&
	       t->y % t->size == 0 && (uint64_t)t->x + t->size <= a->size && (uint64_t)t->y + t->size <= a->size;
}

/* Number of cells of the tile's square that are already owned. */
static uint32_t grid_conflicts(const struct grid *g, const struct rnd_tile *t)
{
	uint32_t c0x = t->x / g->min_tile, c0y = t->y / g->min_tile, n = t->size / g->min_tile, bad = 0;
	for (uint32_t y = c0y; y < c0y + n; y++)
		for (uint32_t x = c0x; x < c0x + n; x++) bad += g->owner[(size_t)y * g->cells + x] != 0;
	return bad;
}

static void grid_set(struct grid *g, const struct rnd_tile *t, uint32_t id)
{
	uint32_t c0x = t->x / g->min_tile, c0y = t->y / g->min_tile, n = t->size / g->min_tile;
	for (uint32_t y = c0y; y < c0y + n; y++)
		for (uint32_t x = c0x; x < c0x + n; x++) g->owner[(size_t)y * g->cells + x] = id;
}

/* Whether some aligned square of `size` texels is entirely free in the reference grid. */
static bool grid_has_free_block(const struct grid *g, uint32_t size)
{
	uint32_t n = size / g->min_tile;
	for (uint32_t by = 0; by < g->cells; by += n)
		for (uint32_t bx = 0; bx < g->cells; bx += n) {
			bool ok = true;
			for (uint32_t y = by; y < by + n && ok; y++)
				for (uint32_t x = bx; x < bx + n; x++)
					if (g->owner[(size_t)y * g->cells + x]) { ok = false; break; }
			if (ok) return true;
		}
	return false;
}

/* Deterministic xorshift64*. */
static uint64_t rng_next(uint64_t *s)
{
	*s ^= *s >> 12; *s ^= *s << 25; *s ^= *s >> 27;
	return *s * 2685821657736338717ull;
}
static uint32_t rng_below(uint64_t *s, uint32_t n) { return (uint32_t)((rng_next(s) >> 33) % n); }

static double occ_of(uint64_t texels, uint32_t size) { return (double)texels / ((double)size * size); }
static bool near_d(double a, double b) { return a - b <= 1e-12 && b - a <= 1e-12; }

/* ---- init / argument checks -------------------------------------------------------------- */

TEST(atlas_init_rejects_bad_args)
{
	struct rnd_atlas a;
	static const uint32_t bad[][2] = {
		{0, 64}, {100, 4}, {8191, 64}, {3, 1}, {8192, 0}, {8192, 48}, {8192, 65},
		{64, 128}, {1024, 2048}, {1, 2}, {0, 0}, {0xffffffffu, 1},
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		memset(&a, 0xab, sizeof a);
		CHECK(!rnd_atlas_init(&a, bad[i][0], bad[i][1]), "init(%u, %u) should fail", bad[i][0], bad[i][1]);
		/* A failed init leaves an inert atlas: alloc fails, free and release are no-ops. */
		struct rnd_tile t = {0, 0, 64, 0};
		CHECK(!rnd_atlas_alloc(&a, 64, &t), "alloc on failed init(%u, %u)", bad[i][0], bad[i][1]);
		rnd_atlas_free(&a, &t);
		CHECK(a.used_tiles == 0 && a.used_texels == 0, "failed init bookkeeping");
		CHECK(rnd_atlas_occupancy(&a) == 0.0, "failed init occupancy");
		rnd_atlas_release(&a);
	}

	static const uint32_t good[][2] = {
		{8192, 64}, {1024, 16}, {64, 64}, {1, 1}, {2, 1}, {4096, 4096}, {2048, 1}, {1u << 31, 1u << 30},
	};
	for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
		CHECK(rnd_atlas_init(&a, good[i][0], good[i][1]), "init(%u, %u) should succeed", good[i][0], good[i][1]);
		CHECK(a.size == good[i][0] && a.min_tile == good[i][1], "fields for init(%u, %u)", good[i][0], good[i][1]);
		CHECK(a.used_tiles == 0 && a.used_texels == 0, "fresh bookkeeping");
		CHECK(rnd_atlas_occupancy(&a) == 0.0, "fresh occupancy");
		rnd_atlas_release(&a);
		CHECK(a.state == NULL, "release clears state");
	}
}

TEST(atlas_alloc_rejects_bad_sizes)
{
	struct rnd_atlas a;
	REQUIRE(rnd_atlas_init(&a, 1024, 32));
	static const uint32_t bad[] = {0, 1, 16, 31, 33, 48, 96, 100, 1000, 1023, 1025, 2048, 4096, 0x80000000u, 0xffffffffu};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		struct rnd_tile t;
		CHECK(!rnd_atlas_alloc(&a, bad[i], &t), "alloc(%u) should fail", bad[i]);
	}
	CHECK(a.used_tiles == 0 && a.used_texels == 0, "rejected allocs leave no trace");
	/* Rejections didn't disturb the tree: the whole atlas is still one free tile. */
	struct rnd_tile full;
	REQUIRE(rnd_atlas_alloc(&a, 1024, &full), "full-size alloc after rejections");
	CHECK(full.x == 0 && full.y == 0 && full.size == 1024, "full tile at %u,%u size %u", full.x, full.y, full.size);
	rnd_atlas_free(&a, &full);
	/* Every legal size works on an empty atlas. */
	for (uint32_t s = 32; s <= 1024; s *= 2) {
		struct rnd_tile t;
		CHECK(rnd_atlas_alloc(&a, s, &t) && tile_well_formed(&a, &t, s), "alloc(%u) on empty atlas", s);
		rnd_atlas_free(&a, &t);
	}
	CHECK(a.used_tiles == 0 && a.used_texels == 0, "all freed");
	rnd_atlas_release(&a);
}

TEST(atlas_single_tile_atlas)
{
	struct rnd_atlas a;
	REQUIRE(rnd_atlas_init(&a, 64, 64));
	struct rnd_tile t, u;
	REQUIRE(rnd_atlas_alloc(&a, 64, &t));
	CHECK(t.x == 0 && t.y == 0 && t.size == 64, "tile %u,%u size %u", t.x, t.y, t.size);
	CHECK(!rnd_atlas_alloc(&a, 64, &u), "second tile in a one-tile atlas");
	CHECK(!rnd_atlas_alloc(&a, 32, &u), "below min_tile");
	CHECK(rnd_atlas_occupancy(&a) == 1.0, "full");
	rnd_atlas_free(&a, &t);
	CHECK(rnd_atlas_occupancy(&a) == 0.0, "empty");
	CHECK(rnd_atlas_alloc(&a, 64, &u), "again after free");
	rnd_atlas_release(&a);
}

/* ---- filling with one size ----------------------------------------------------------------- */

static void fill_case(uint32_t size, uint32_t min_tile, uint32_t tile)
{
	struct rnd_atlas a;
	struct grid g;
	REQUIRE(rnd_atlas_init(&a, size, min_tile), "init(%u, %u)", size, min_tile);
	REQUIRE(grid_init(&g, size, min_tile));
	uint32_t per_side = size / tile, want = per_side * per_side;
	struct rnd_tile *tiles = calloc(want + 1, sizeof *tiles);
	REQUIRE(tiles);
	uint32_t n = 0;
	bool overlap = false, malformed = false;
	while (n <= want && rnd_atlas_alloc(&a, tile, &tiles[n])) {
		if (!tile_well_formed(&a, &tiles[n], tile)) { malformed = true; break; }
		if (grid_conflicts(&g, &tiles[n])) overlap = true;
		grid_set(&g, &tiles[n], n + 1);
		n++;
	}
	CHECK(!malformed, "fill %u/%u with %u: malformed tile %u,%u size %u", size, min_tile, tile,
	      tiles[n].x, tiles[n].y, tiles[n].size);
	CHECK(!overlap, "fill %u/%u with %u: tiles overlap", size, min_tile, tile);
	CHECK(n == want, "fill %u/%u with %u: got %u tiles, want %u", size, min_tile, tile, n, want);
	CHECK(!grid_has_free_block(&g, min_tile), "fill %u/%u with %u: grid not covered", size, min_tile, tile);
	CHECK(a.used_tiles == want && a.used_texels == (uint64_t)size * size, "fill bookkeeping: %u tiles", a.used_tiles);
	CHECK(rnd_atlas_occupancy(&a) == 1.0, "fill occupancy %g", rnd_atlas_occupancy(&a));
	struct rnd_tile extra;
	CHECK(!rnd_atlas_alloc(&a, tile, &extra), "one more %u tile in a full atlas", tile);
	CHECK(!rnd_atlas_alloc(&a, min_tile, &extra), "one more min tile in a full atlas");
	CHECK(a.used_tiles == want, "failed allocs don't count");
	/* Free every other one, then the rest: everything merges back to one free atlas. */
	for (uint32_t i = 0; i < n; i += 2) rnd_atlas_free(&a, &tiles[i]);
	for (uint32_t i = 1; i < n; i += 2) rnd_atlas_free(&a, &tiles[i]);
	CHECK(a.used_tiles == 0 && a.used_texels == 0, "fill: all freed");
	CHECK(rnd_atlas_alloc(&a, size, &extra), "fill %u/%u with %u: full-size alloc after freeing all", size, min_tile, tile);
	free(tiles);
	grid_release(&g);
	rnd_atlas_release(&a);
}

TEST(atlas_fill_one_size)
{
	fill_case(1024, 64, 64);
	fill_case(1024, 64, 128);
	fill_case(1024, 64, 512);
	fill_case(1024, 64, 1024);
	fill_case(1024, 16, 256);
	fill_case(8192, 64, 64);   /* 16384 tiles of the documented config (~1 s: alloc rescans full subtrees) */
	fill_case(8192, 64, 1024);
	fill_case(2048, 1, 64);    /* 12 levels, the deepest init accepts */
	fill_case(256, 1, 4);
	fill_case(1u << 31, 1u << 30, 1u << 30);
}

/* ---- fragmentation / merging ---------------------------------------------------------------- */

TEST(atlas_fragmentation_quarters)
{
	struct rnd_atlas a;
	REQUIRE(rnd_atlas_init(&a, 1024, 64));
	struct rnd_tile q[4], t, big;
	for (int i = 0; i < 4; i++) REQUIRE(rnd_atlas_alloc(&a, 512, &q[i]), "quarter %d", i);
	bool seen[4] = {false};
	for (int i = 0; i < 4; i++) {
		CHECK(tile_well_formed(&a, &q[i], 512), "quarter %d well formed", i);
		seen[(q[i].y / 512) * 2 + q[i].x / 512] = true;
	}
	CHECK(seen[0] && seen[1] && seen[2] && seen[3], "four distinct quarters");
	CHECK(!rnd_atlas_alloc(&a, 64, &t), "full atlas");
	CHECK(rnd_atlas_occupancy(&a) == 1.0, "full occupancy");

	rnd_atlas_free(&a, &q[2]);
	CHECK(rnd_atlas_occupancy(&a) == 0.75, "occupancy %g after freeing a quarter", rnd_atlas_occupancy(&a));
	CHECK(!rnd_atlas_alloc(&a, 1024, &big), "full-size alloc must fail with three quarters used");
	REQUIRE(rnd_atlas_alloc(&a, 512, &t), "quarter-size alloc into the hole");
	CHECK(t.x == q[2].x && t.y == q[2].y, "the hole is reused: %u,%u vs %u,%u", t.x, t.y, q[2].x, q[2].y);
	rnd_atlas_free(&a, &t);

	/* Fill the hole with smaller tiles instead; they must all land inside it. */
	struct rnd_tile s[4];
	for (int i = 0; i < 4; i++) {
		REQUIRE(rnd_atlas_alloc(&a, 256, &s[i]), "256 tile %d in the hole", i);
		CHECK(s[i].x >= q[2].x && s[i].x < q[2].x + 512 && s[i].y >= q[2].y && s[i].y < q[2].y + 512,
		      "256 tile %d at %u,%u is outside the free quarter", i, s[i].x, s[i].y);
	}
	CHECK(!rnd_atlas_alloc(&a, 256, &t), "hole exhausted");
	CHECK(!rnd_atlas_alloc(&a, 512, &t), "no quarter left");
	/* Free one small tile: a small alloc fits, a quarter or the whole atlas does not. */
	rnd_atlas_free(&a, &s[1]);
	CHECK(!rnd_atlas_alloc(&a, 512, &t), "quarter still split");
	CHECK(!rnd_atlas_alloc(&a, 1024, &t), "atlas still mostly used");
	REQUIRE(rnd_atlas_alloc(&a, 128, &t), "128 into the freed 256");
	CHECK(t.x >= s[1].x && t.x < s[1].x + 256 && t.y >= s[1].y && t.y < s[1].y + 256, "128 lands in freed 256");
	rnd_atlas_free(&a, &t);
	/* Freeing the rest of the small tiles merges the quarter back. */
	rnd_atlas_free(&a, &s[0]);
	rnd_atlas_free(&a, &s[2]);
	rnd_atlas_free(&a, &s[3]);
	REQUIRE(rnd_atlas_alloc(&a, 512, &t), "quarter again after merging the small tiles");
	CHECK(t.x == q[2].x && t.y == q[2].y, "merged quarter at %u,%u", t.x, t.y);
	rnd_atlas_free(&a, &t);
	/* And everything else: the whole atlas is one tile again. */
	rnd_atlas_free(&a, &q[0]);
	rnd_atlas_free(&a, &q[1]);
	CHECK(!rnd_atlas_alloc(&a, 1024, &big), "one quarter still used");
	rnd_atlas_free(&a, &q[3]);
	CHECK(a.used_tiles == 0 && a.used_texels == 0, "all freed");
	REQUIRE(rnd_atlas_alloc(&a, 1024, &big), "full-size alloc after freeing everything");
	CHECK(big.x == 0 && big.y == 0 && big.size == 1024, "full tile");
	rnd_atlas_release(&a);
}

TEST(atlas_free_all_merges_back)
{
	struct rnd_atlas a;
	REQUIRE(rnd_atlas_init(&a, 2048, 32));
	struct rnd_tile t[64], big;
	static const uint32_t sizes[] = {32, 256, 64, 32, 512, 128, 32, 64, 1024, 32, 128};
	uint32_t n = 0;
	for (uint32_t round = 0; round < 4; round++)
		for (size_t i = 0; i < sizeof sizes / sizeof sizes[0] && n < 64; i++)
			if (rnd_atlas_alloc(&a, sizes[i], &t[n])) n++;
	REQUIRE(n > 10, "allocated %u", n);
	CHECK(!rnd_atlas_alloc(&a, 2048, &big), "full-size alloc while tiles are live");
	/* Free in a scrambled order: odd indices backwards, then even ones forwards. */
	for (uint32_t i = n; i-- > 0;)
		if (i & 1) rnd_atlas_free(&a, &t[i]);
	for (uint32_t i = 0; i < n; i += 2) rnd_atlas_free(&a, &t[i]);
	CHECK(a.used_tiles == 0 && a.used_texels == 0, "used %u tiles %llu texels", a.used_tiles,
	      (unsigned long long)a.used_texels);
	CHECK(rnd_atlas_occupancy(&a) == 0.0, "empty");
	REQUIRE(rnd_atlas_alloc(&a, 2048, &big), "full-size alloc after freeing everything");
	CHECK(big.x == 0 && big.y == 0 && big.size == 2048, "full tile");
	rnd_atlas_free(&a, &big);
	/* After merging, the smallest size can be filled completely again. */
	uint32_t m = 0;
	struct rnd_tile s;
	while (rnd_atlas_alloc(&a, 32, &s)) m++;
	CHECK(m == 64 * 64, "refill with min tiles: %u", m);
	rnd_atlas_release(&a);
}

/* ---- bookkeeping ------------------------------------------------------------------------------ */

TEST(atlas_bookkeeping)
{
	struct rnd_atlas a;
	REQUIRE(rnd_atlas_init(&a, 1024, 64));
	struct rnd_tile t512, t64, t128, t;
	REQUIRE(rnd_atlas_alloc(&a, 512, &t512));
	CHECK(a.used_tiles == 1 && a.used_texels == 512u * 512u, "after 512: %u %llu", a.used_tiles,
	      (unsigned long long)a.used_texels);
	CHECK(rnd_atlas_occupancy(&a) == 0.25, "occupancy %g", rnd_atlas_occupancy(&a));
	REQUIRE(rnd_atlas_alloc(&a, 64, &t64));
	REQUIRE(rnd_atlas_alloc(&a, 128, &t128));
	uint64_t want = 512u * 512u + 64u * 64u + 128u * 128u;
	CHECK(a.used_tiles == 3 && a.used_texels == want, "after 3 allocs: %u %llu", a.used_tiles,
	      (unsigned long long)a.used_texels);
	CHECK(near_d(rnd_atlas_occupancy(&a), occ_of(want, 1024)), "occupancy %g", rnd_atlas_occupancy(&a));
	CHECK(!rnd_atlas_alloc(&a, 1024, &t), "full-size fails");
	CHECK(!rnd_atlas_alloc(&a, 96, &t), "bad size fails");
	CHECK(a.used_tiles == 3 && a.used_texels == want, "failed allocs change nothing");
	rnd_atlas_free(&a, &t64);
	want -= 64u * 64u;
	CHECK(a.used_tiles == 2 && a.used_texels == want, "after free 64: %u %llu", a.used_tiles,
	      (unsigned long long)a.used_texels);
	rnd_atlas_free(&a, &t512);
	rnd_atlas_free(&a, &t128);
	CHECK(a.used_tiles == 0 && a.used_texels == 0, "after freeing all");
	CHECK(rnd_atlas_occupancy(&a) == 0.0, "occupancy 0");
	rnd_atlas_release(&a);
	CHECK(a.used_tiles == 0 && a.used_texels == 0 && a.size == 0, "release zeroes");
	CHECK(rnd_atlas_occupancy(&a) == 0.0, "released occupancy");
}

TEST(atlas_double_free_harmless)
{
	struct rnd_atlas a;
	REQUIRE(rnd_atlas_init(&a, 1024, 64));
	struct rnd_tile x, y, t;
	REQUIRE(rnd_atlas_alloc(&a, 256, &x));
	REQUIRE(rnd_atlas_alloc(&a, 256, &y));
	rnd_atlas_free(&a, &x);
	rnd_atlas_free(&a, &x);
	CHECK(a.used_tiles == 1 && a.used_texels == 256u * 256u, "double free counted once: %u %llu", a.used_tiles,
	      (unsigned long long)a.used_texels);
	/* y is still allocated: filling the rest with 256 tiles never returns y's square. */
	uint32_t n = 0;
	struct rnd_tile fill[16];
	while (n < 16 && rnd_atlas_alloc(&a, 256, &fill[n])) {
		CHECK(!(fill[n].x == y.x && fill[n].y == y.y), "y's square handed out again after a double free of x");
		n++;
	}
	CHECK(n == 15, "15 more 256 tiles fit, got %u", n);
	for (uint32_t i = 0; i < n; i++) rnd_atlas_free(&a, &fill[i]);
	rnd_atlas_free(&a, &y);
	rnd_atlas_free(&a, &y);
	CHECK(a.used_tiles == 0 && a.used_texels == 0, "all freed");

	/* A stale handle freed again after its square merged and was reallocated as a bigger tile
	 * must not free the bigger tile. */
	struct rnd_tile small, big;
	REQUIRE(rnd_atlas_alloc(&a, 64, &small));
	rnd_atlas_free(&a, &small);
	REQUIRE(rnd_atlas_alloc(&a, 1024, &big));
	rnd_atlas_free(&a, &small);
	CHECK(a.used_tiles == 1 && a.used_texels == 1024u * 1024u, "stale free after merge: %u %llu", a.used_tiles,
	      (unsigned long long)a.used_texels);
	CHECK(!rnd_atlas_alloc(&a, 64, &t), "big tile still covers the atlas");
	rnd_atlas_free(&a, &big);
	rnd_atlas_free(&a, &big);
	CHECK(a.used_tiles == 0 && a.used_texels == 0, "double free of the full tile");
	REQUIRE(rnd_atlas_alloc(&a, 1024, &big), "full tile again");
	rnd_atlas_free(&a, &big);

	/* A handle whose node is out of range is ignored. */
	struct rnd_tile junk = {0, 0, 64, 0xffffffffu};
	REQUIRE(rnd_atlas_alloc(&a, 64, &t));
	rnd_atlas_free(&a, &junk);
	junk.node = a.node_count;
	rnd_atlas_free(&a, &junk);
	CHECK(a.used_tiles == 1, "junk frees ignored");
	rnd_atlas_free(&a, &t);
	CHECK(a.used_tiles == 0, "real free");
	rnd_atlas_release(&a);
	/* Free after release is a no-op. */
	rnd_atlas_free(&a, &t);
	CHECK(a.used_tiles == 0, "free after release");
}

/* ---- randomized against the reference grid ---------------------------------------------------- */

struct live { struct rnd_tile t; uint32_t id; };

static void random_case(uint32_t size, uint32_t min_tile, uint64_t seed, uint32_t steps)
{
	struct rnd_atlas a;
	struct grid g;
	REQUIRE(rnd_atlas_init(&a, size, min_tile), "init(%u, %u)", size, min_tile);
	REQUIRE(grid_init(&g, size, min_tile));
	uint32_t max_live = g.cells * g.cells, levels = 0;
	while ((size >> levels) > min_tile) levels++; /* legal sizes: min_tile << 0 .. min_tile << levels */
	struct live *live = calloc(max_live, sizeof *live);
	REQUIRE(live);
	uint32_t nlive = 0, next_id = 1, allocs = 0, fails = 0, frees = 0, failures = 0;
	uint64_t texels = 0;
	struct rnd_tile last_freed = {0};
	bool have_last_freed = false;

	for (uint32_t step = 0; step < steps && failures < 8; step++) {
		uint32_t r = rng_below(&seed, 100);
		/* Bias: mostly allocate while sparse, mostly free when dense, so the atlas swings
		 * between fragmented and nearly full. */
		uint32_t alloc_pct = texels * 4 < (uint64_t)size * size * 3 ? 65 : 35;
		if (r < 3 && have_last_freed) {
			/* Double free right after the free: must be a no-op. */
			uint32_t ut = a.used_tiles;
			uint64_t ux = a.used_texels;
			rnd_atlas_free(&a, &last_freed);
			if (a.used_tiles != ut || a.used_texels != ux) {
				failures++;
				CHECK(false, "step %u: double free of %u,%u size %u changed bookkeeping", step, last_freed.x,
				      last_freed.y, last_freed.size);
			}
		} else if (r < 3 + alloc_pct || nlive == 0) {
			/* Size: small sizes much more likely (level drawn twice, take the deeper). */
			uint32_t l1 = rng_below(&seed, levels + 1), l2 = rng_below(&seed, levels + 1);
			uint32_t s = min_tile << (l1 < l2 ? l1 : l2);
			bool expect = grid_has_free_block(&g, s);
			struct rnd_tile t;
			memset(&t, 0xcd, sizeof t);
			bool got = rnd_atlas_alloc(&a, s, &t);
			if (got != expect) {
				failures++;
				CHECK(false, "step %u: alloc(%u) returned %d but a free aligned block %s", step, s, got,
				      expect ? "exists" : "does not exist");
			}
			if (got) {
				if (!tile_well_formed(&a, &t, s)) {
					failures++;
					CHECK(false, "step %u: alloc(%u) gave malformed tile %u,%u size %u", step, s, t.x, t.y, t.size);
					continue;
				}
				uint32_t c = grid_conflicts(&g, &t);
				if (c) {
					failures++;
					CHECK(false, "step %u: alloc(%u) at %u,%u overlaps %u live cells", step, s, t.x, t.y, c);
				}
				for (uint32_t i = 0; i < nlive; i++)
					if (live[i].t.node == t.node) {
						failures++;
						CHECK(false, "step %u: node %u handed out twice", step, t.node);
					}
				grid_set(&g, &t, next_id);
				REQUIRE(nlive < max_live);
				live[nlive].t = t;
				live[nlive].id = next_id++;
				nlive++;
				texels += (uint64_t)s * s;
				allocs++;
			} else {
				fails++;
			}
			have_last_freed = false; /* a stale handle may be reused by an alloc */
		} else {
			uint32_t i = rng_below(&seed, nlive);
			struct rnd_tile t = live[i].t;
			rnd_atlas_free(&a, &t);
			grid_set(&g, &t, 0);
			texels -= (uint64_t)t.size * t.size;
			live[i] = live[--nlive];
			last_freed = t;
			have_last_freed = true;
			frees++;
		}
		if (a.used_tiles != nlive || a.used_texels != texels) {
			failures++;
			CHECK(false, "step %u: bookkeeping %u tiles %llu texels, want %u %llu", step, a.used_tiles,
			      (unsigned long long)a.used_texels, nlive, (unsigned long long)texels);
		}
		if (!near_d(rnd_atlas_occupancy(&a), occ_of(texels, size))) {
			failures++;
			CHECK(false, "step %u: occupancy %g want %g", step, rnd_atlas_occupancy(&a), occ_of(texels, size));
		}
	}
	CHECK(failures == 0, "%u/%u/%llu: %u failures", size, min_tile, (unsigned long long)seed, failures);
	/* The run must actually have exercised both outcomes and real churn. */
	CHECK(allocs > steps / 4 && frees > steps / 8 && fails > 0, "coverage: %u allocs, %u frees, %u failed allocs",
	      allocs, frees, fails);

	/* Free everything left, in random order: the atlas merges back to one tile. */
	while (nlive) {
		uint32_t i = rng_below(&seed, nlive);
		rnd_atlas_free(&a, &live[i].t);
		live[i] = live[--nlive];
	}
	CHECK(a.used_tiles == 0 && a.used_texels == 0, "drained: %u %llu", a.used_tiles, (unsigned long long)a.used_texels);
	CHECK(rnd_atlas_occupancy(&a) == 0.0, "drained occupancy");
	struct rnd_tile full;
	CHECK(rnd_atlas_alloc(&a, size, &full) && full.size == size && full.x == 0 && full.y == 0,
	      "full-size alloc after draining %u/%u", size, min_tile);
	free(live);
	grid_release(&g);
	rnd_atlas_release(&a);
}

TEST(atlas_random_against_reference)
{
	random_case(1024, 16, 0x9e3779b97f4a7c15ull, 20000);
	random_case(8192, 64, 0x243f6a8885a308d3ull, 8000);
	random_case(256, 64, 0x13198a2e03707344ull, 5000);
	random_case(1024, 1, 0xa4093822299f31d0ull, 3000); /* 11 levels */
}
