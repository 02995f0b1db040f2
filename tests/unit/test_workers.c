/* tests — srv_default_workers(): --workers follows the cgroup CPU quota, not the host's cores.
 * Each case builds a fake cgroup tree (and a fake /proc/self/cgroup) in a temporary directory. */
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "srv.h"
#include "test.h"

struct fake { char root[64]; char self[96]; };

static void put(const char *dir, const char *rel, const char *text)
{
	char path[256];
	snprintf(path, sizeof path, "%s/%s", dir, rel);
	/* Parents first: rel may name nested cgroup directories. */
	for (char *p = path + strlen(dir) + 1; (p = strchr(p, '/')); p++) {
		*p = 0;
		mkdir(path, 0755);
		*p = '/';
	}
	FILE *f = fopen(path, "w");
	if (f) {
		fputs(text, f);
		fclose(f);
	}
}

static int fake_init(struct fake *fk, const char *self_cgroup)
{
	strcpy(fk->root, "/tmp/umbra-cg.XXXXXX");
	if (!mkdtemp(fk->root))
		return -1;
	snprintf(fk->self, sizeof fk->self, "%s/self-cgroup", fk->root);
	put(fk->root, "self-cgroup", self_cgroup);
	return 0;
}

static void fake_release(struct fake *fk)
{
	char cmd[128];
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", fk->root);
	if (system(cmd) != 0)
		fprintf(stderr, "cannot remove %s\n", fk->root);
}

TEST(workers_cgroup_v2_quota_rounds_up)
{
	struct fake fk;
	REQUIRE(fake_init(&fk, "0::/\n") == 0);
	put(fk.root, "cpu.max", "250000 100000\n"); /* 2.5 CPUs */
	CHECK(srv_default_workers(fk.root, fk.self, 64) == 3, "got %u", srv_default_workers(fk.root, fk.self, 64));
	CHECK(srv_default_workers(fk.root, fk.self, 2) == 2, "the quota never raises the CPU count");
	put(fk.root, "cpu.max", "50000 100000\n"); /* half a CPU: still one worker */
	CHECK(srv_default_workers(fk.root, fk.self, 64) == 1, "got %u", srv_default_workers(fk.root, fk.self, 64));
	fake_release(&fk);
}

TEST(workers_cgroup_v2_max_is_no_quota)
{
	struct fake fk;
	REQUIRE(fake_init(&fk, "0::/\n") == 0);
	put(fk.root, "cpu.max", "max 100000\n");
	/* v1 files are ignored when v2's cpu.max exists. */
	put(fk.root, "cpu/cpu.cfs_quota_us", "100000\n");
	put(fk.root, "cpu/cpu.cfs_period_us", "100000\n");
	CHECK(srv_default_workers(fk.root, fk.self, 16) == 16, "got %u", srv_default_workers(fk.root, fk.self, 16));
	fake_release(&fk);
}

TEST(workers_cgroup_v2_own_cgroup_first)
{
	struct fake fk;
	REQUIRE(fake_init(&fk, "0::/system.slice/umbrad.service\n") == 0);
	put(fk.root, "system.slice/umbrad.service/cpu.max", "400000 100000\n"); /* CPUQuota=400% */
	put(fk.root, "cpu.max", "max 100000\n");
	CHECK(srv_default_workers(fk.root, fk.self, 32) == 4, "got %u", srv_default_workers(fk.root, fk.self, 32));
	fake_release(&fk);
}

TEST(workers_cgroup_v1_cfs_quota)
{
	struct fake fk;
	REQUIRE(fake_init(&fk, "4:cpu,cpuacct:/docker/abc\n") == 0);
	put(fk.root, "cpu/cpu.cfs_quota_us", "300000\n");
	put(fk.root, "cpu/cpu.cfs_period_us", "100000\n");
	CHECK(srv_default_workers(fk.root, fk.self, 8) == 3, "got %u", srv_default_workers(fk.root, fk.self, 8));
	put(fk.root, "cpu/cpu.cfs_quota_us", "-1\n");
	CHECK(srv_default_workers(fk.root, fk.self, 8) == 8, "quota -1 means none");
	fake_release(&fk);
}

TEST(workers_no_cgroup_files)
{
	struct fake fk;
	REQUIRE(fake_init(&fk, "") == 0);
	CHECK(srv_default_workers(fk.root, fk.self, 6) == 6, "no files: the CPU count");
	CHECK(srv_default_workers(fk.root, NULL, 0) == 1, "never 0");
	CHECK(srv_default_workers("/nonexistent", "/nonexistent", 5) == 5, "missing mount");
	fake_release(&fk);
}
