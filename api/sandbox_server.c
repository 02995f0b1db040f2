/*
 * api/sandbox_server — the fork server's process, from the daemon's side (see sandbox.h): found,
 * started with posix_spawn on first use, restarted when it died, and each job's request sent
 * to it over the control socket. api/sandbox.c runs the jobs.
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>
#include "sandbox.h"
#include "sandbox_stats.h"

extern char **environ;

#define CTL_SEND_MS 2000

static pthread_mutex_t start_mu = PTHREAD_MUTEX_INITIALIZER;
static int ctl_fd = -1;
static pid_t server_pid = -1;
static char helper[PATH_MAX];

/* UMBRA_IMPORT_HELPER, else umbra-import next to the running executable, else one directory
 * up (the test binaries live in build/tests/). With start_mu held. */
static void find_helper(void)
{
	const char *env = getenv("UMBRA_IMPORT_HELPER");
	if (env && env[0]) {
		snprintf(helper, sizeof helper, "%s", env);
		return;
	}
	char exe[PATH_MAX];
	ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
	if (n <= 0) {
		snprintf(helper, sizeof helper, "umbra-import");
		return;
	}
	exe[n] = 0;
	char *slash = strrchr(exe, '/');
	if (slash) *slash = 0;
	snprintf(helper, sizeof helper, "%.*s/umbra-import", PATH_MAX - 16, exe);
	if (access(helper, X_OK) == 0 || !(slash = strrchr(exe, '/'))) return;
	*slash = 0;
	char up[PATH_MAX];
	snprintf(up, sizeof up, "%.*s/umbra-import", PATH_MAX - 16, exe);
	if (access(up, X_OK) == 0) memcpy(helper, up, sizeof up);
}

const char *api_sandbox_helper_path(void)
{
	pthread_mutex_lock(&start_mu);
	if (!helper[0]) find_helper();
	pthread_mutex_unlock(&start_mu);
	return helper;
}

/* With start_mu held. */
static void stop_server(void)
{
	if (ctl_fd >= 0) close(ctl_fd);
	ctl_fd = -1;
	if (server_pid > 0) {
		/* Closing the control socket ends it; SIGKILL in case it is what went wrong. */
		kill(server_pid, SIGKILL);
		waitpid(server_pid, NULL, 0);
	}
	server_pid = -1;
}

char **api_sbx_helper_env(char *const *env, char **own)
{
	static const char tunable[] = API_SBX_TUNABLES;
	size_t n = 0;
	const char *old = NULL;
	for (; env[n]; n++)
		if (!strncmp(env[n], "GLIBC_TUNABLES=", 15)) old = env[n] + 15;
	char **out = calloc(n + 2, sizeof *out);
	size_t len = sizeof "GLIBC_TUNABLES=" + sizeof tunable + (old ? strlen(old) + 1 : 0);
	*own = malloc(len);
	if (!out || !*own) {
		free(out);
		free(*own);
		return *own = NULL, NULL;
	}
	snprintf(*own, len, "GLIBC_TUNABLES=%s%s%s", old ? old : "", old ? ":" : "", tunable);
	size_t k = 0;
	for (size_t i = 0; i < n; i++)
		if (strncmp(env[i], "GLIBC_TUNABLES=", 15)) out[k++] = env[i];
	out[k] = *own;
	return out;
}

/* With start_mu held. posix_spawn (vfork-like) is safe in a multithreaded process. */
static int start_server(char *err, size_t errsize)
{
	if (!helper[0]) find_helper();
	int sv[2];
	if (socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv) < 0) {
		snprintf(err, errsize, "cannot create the importer's socket: %s", strerror(errno));
		return -1;
	}
	/* Above fd 3, so the dup2 to 3 below always happens and clears close-on-exec. */
	int child_end = fcntl(sv[1], F_DUPFD_CLOEXEC, 10);
	posix_spawn_file_actions_t fa;
	posix_spawnattr_t at;
	posix_spawn_file_actions_init(&fa);
	posix_spawnattr_init(&at);
	posix_spawn_file_actions_adddup2(&fa, child_end, API_SBX_CTL_FD);
	posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
	posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
	sigset_t none, all;
	sigemptyset(&none);
	sigfillset(&all);
	sigdelset(&all, SIGKILL);
	sigdelset(&all, SIGSTOP);
	posix_spawnattr_setsigmask(&at, &none);
	posix_spawnattr_setsigdefault(&at, &all);
	posix_spawnattr_setflags(&at, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
	char *argv[] = {helper, "--fork-server", NULL}, *tunables = NULL, **env = api_sbx_helper_env(environ, &tunables);
	pid_t pid;
	int rc = child_end < 0 ? errno : posix_spawn(&pid, helper, &fa, &at, argv, env ? env : environ);
	free(env);
	free(tunables);
	posix_spawn_file_actions_destroy(&fa);
	posix_spawnattr_destroy(&at);
	if (child_end >= 0) close(child_end);
	close(sv[1]);
	if (rc) {
		close(sv[0]);
		snprintf(err, errsize, "cannot start the model importer (umbra-import): %s", strerror(rc));
		return -1;
	}
	ctl_fd = sv[0];
	server_pid = pid;
	api_sbx_stats_server_started();
	return 0;
}

/* Restarts the fork server once when it is gone. The lock covers one sendmsg on a socket the
 * fork server drains at once, bounded by CTL_SEND_MS. */
int api_sbx_send(const struct api_sbx_request *rq, int data_fd, int status_fd, int reply_fd, char *err,
                 size_t errsize)
{
	int fds[3] = {data_fd, status_fd, reply_fd};
	union { struct cmsghdr h; char buf[CMSG_SPACE(sizeof fds)]; } cm;
	memset(&cm, 0, sizeof cm);
	struct iovec iov = {(void *)rq, sizeof *rq};
	struct msghdr msg = {.msg_iov = &iov, .msg_iovlen = 1, .msg_control = cm.buf, .msg_controllen = sizeof cm.buf};
	struct cmsghdr *c = CMSG_FIRSTHDR(&msg);
	c->cmsg_level = SOL_SOCKET;
	c->cmsg_type = SCM_RIGHTS;
	c->cmsg_len = CMSG_LEN(sizeof fds);
	memcpy(CMSG_DATA(c), fds, sizeof fds);
	int rc = -1;
	pthread_mutex_lock(&start_mu);
	for (int attempt = 0; attempt < 2 && rc < 0; attempt++) {
		if (ctl_fd < 0 && start_server(err, errsize) < 0) break;
		int64_t until = (int64_t)api_clock_ms() + CTL_SEND_MS;
		for (;;) {
			if (sendmsg(ctl_fd, &msg, MSG_NOSIGNAL | MSG_DONTWAIT) == (ssize_t)sizeof *rq) { rc = 0; break; }
			if (errno == EINTR) continue;
			if (errno != EAGAIN || (int64_t)api_clock_ms() >= until) {
				snprintf(err, errsize, "the model importer does not answer (%s)", strerror(errno));
				stop_server(); /* dead or stuck: the next attempt starts a fresh one */
				break;
			}
			struct pollfd p = {ctl_fd, POLLOUT, 0};
			poll(&p, 1, 50);
		}
	}
	pthread_mutex_unlock(&start_mu);
	return rc;
}
