/*
 * api/sandbox_child — the helper side of api/sandbox.h: the fork server's loop and the
 * sandboxed child that does one job. Runs only inside `umbra-import --fork-server`, a
 * single-threaded process (forking it is safe), never inside the daemon.
 *
 * The fork server is the parent of every child, so it alone can reap them, and a pid it kills
 * at the timeout cannot belong to another process yet. It learns of exits through SIGCHLD,
 * which stays blocked except inside ppoll(): no handler ever runs in the middle of its work.
 * When the control socket reaches EOF (the daemon exited or restarts it) it kills its children
 * and exits; children also get SIGKILL if it dies (PR_SET_PDEATHSIG).
 */
#include <errno.h>
#include <fcntl.h>
#include <malloc.h>
#include <poll.h>
#include <seccomp.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <jansson.h>
#include "model_import.h"
#include "model_lod.h"
#include "model_wire.h"
#include "sandbox.h"
#include "workers.h"

#define SBX_SANITIZED API_SBX_SANITIZED

/* Set by the helper's malloc wrappers (api/helper/umbra_import.c) when an allocation fails. */
extern volatile sig_atomic_t api_sbx_alloc_failed;

/* ---- the child ---- */

static void on_fatal(int sig)
{
	/* A crash right after an allocation failed is the memory limit's doing, not the file's. */
	if (api_sbx_alloc_failed) _exit(API_SBX_EXIT_OOM);
	(void)sig; /* SA_RESETHAND: returning re-raises it with the default action */
}

/* Only what parsing and answering need. Sanitizer builds answer EPERM instead of killing: the
 * sanitizer runtime makes calls of its own (sigaltstack, /proc/self/maps for a report), and a
 * test build should report a bug rather than die of its instrumentation; opening a file is
 * refused all the same. */
static int apply_filter(void)
{
	scmp_filter_ctx f = seccomp_init(SBX_SANITIZED ? SCMP_ACT_ERRNO(EPERM) : SCMP_ACT_KILL_PROCESS);
	if (!f) return -1;
	static const int allow[] = {
		SCMP_SYS(read), SCMP_SYS(write), SCMP_SYS(readv), SCMP_SYS(writev), SCMP_SYS(close),
		SCMP_SYS(lseek), SCMP_SYS(fstat), SCMP_SYS(brk), SCMP_SYS(munmap), SCMP_SYS(mremap),
		SCMP_SYS(madvise), SCMP_SYS(futex), SCMP_SYS(exit), SCMP_SYS(exit_group),
		SCMP_SYS(rt_sigreturn), SCMP_SYS(rt_sigaction), SCMP_SYS(rt_sigprocmask), SCMP_SYS(getpid),
		SCMP_SYS(gettid), SCMP_SYS(clock_gettime), SCMP_SYS(gettimeofday), SCMP_SYS(getrandom),
		SCMP_SYS(sched_yield), SCMP_SYS(sigaltstack),
		/* glibc's qsort asks for the machine's memory (sysconf(_SC_PHYS_PAGES)) before sorting
		 * more than 1 KiB: the join sorts the corners around a cone's apex with it. */
		SCMP_SYS(sysinfo),
	};
	int rc = 0;
	for (size_t i = 0; i < sizeof allow / sizeof allow[0] && !rc; i++)
		rc = seccomp_rule_add(f, SCMP_ACT_ALLOW, allow[i], 0);
	/* Memory, never executable; signals only to itself (abort() raises SIGABRT). */
	if (!rc) rc = seccomp_rule_add(f, SCMP_ACT_ALLOW, SCMP_SYS(mmap), 1, SCMP_A2(SCMP_CMP_MASKED_EQ, PROT_EXEC, 0));
	if (!rc) rc = seccomp_rule_add(f, SCMP_ACT_ALLOW, SCMP_SYS(mprotect), 1, SCMP_A2(SCMP_CMP_MASKED_EQ, PROT_EXEC, 0));
	if (!rc) rc = seccomp_rule_add(f, SCMP_ACT_ALLOW, SCMP_SYS(tgkill), 1, SCMP_A0(SCMP_CMP_EQ, (scmp_datum_t)getpid()));
	if (!rc) rc = seccomp_rule_add(f, SCMP_ACT_ALLOW, SCMP_SYS(kill), 1, SCMP_A0(SCMP_CMP_EQ, (scmp_datum_t)getpid()));
	/* TSYNC: the filter covers the import's threads (started just before) as well; no clone
	 * is allowed, so none can be started after. */
	if (!rc) rc = seccomp_attr_set(f, SCMP_FLTATR_CTL_TSYNC, 1);
	if (!rc) rc = seccomp_load(f);
	seccomp_release(f);
	return rc ? -1 : 0;
}

static int set_limits(const struct api_sbx_request *rq)
{
	/* the CPU time of all the import's threads together */
	rlim_t cpu = (rq->timeout_ms + 999) / 1000 * (rq->threads > 1 ? rq->threads : 1);
	struct rlimit r_cpu = {cpu ? cpu : 1, (cpu ? cpu : 1) + 1}, zero = {0, 0};
	/* The only file it can write is its reply file, up to the size the daemon allows. */
	struct rlimit r_fsize = {rq->reply_size, rq->reply_size};
	struct rlimit r_nofile = {API_SBX_REPLY_FD + 1, API_SBX_REPLY_FD + 1};
	if (setrlimit(RLIMIT_CPU, &r_cpu) || setrlimit(RLIMIT_FSIZE, &r_fsize) || setrlimit(RLIMIT_CORE, &zero) ||
	    setrlimit(RLIMIT_NOFILE, &r_nofile) || setrlimit(RLIMIT_NPROC, &zero))
		return -1;
	/* The sanitizers reserve terabytes of address space for their shadow: no RLIMIT_AS there. */
	if (!SBX_SANITIZED && rq->memory) {
		struct rlimit r_as = {rq->memory, rq->memory};
		if (setrlimit(RLIMIT_AS, &r_as)) return -1;
	}
	return 0;
}

static bool io_all(int fd, void *buf, size_t n, bool wr)
{
	uint8_t *p = buf;
	while (n) {
		ssize_t r = wr ? write(fd, p, n) : read(fd, p, n);
		if (r < 0 && errno == EINTR) continue;
		if (r <= 0) return false;
		p += r;
		n -= (size_t)r;
	}
	return true;
}

/* What a job answers; emit() writes it twice: once to size it, once where the daemon maps it. */
struct answer {
	enum api_wire_kind kind;
	enum api_wire_status st;
	char err[API_WIRE_MAX_MESSAGE];
	struct api_model m;              /* MODEL; LEVELS: the model whose meshes carry them */
	uint8_t *px;                     /* IMAGE */
	uint32_t w, h;
};

static void emit(const struct answer *a, struct api_wire_buf *b)
{
	api_wire_put_header(b, a->kind, a->st, a->st == API_WIRE_OK ? NULL : a->err);
	if (a->st != API_WIRE_OK) return;
	if (a->kind == API_WIRE_IMAGE) api_wire_put_image(b, a->px, a->w, a->h);
	else if (a->kind == API_WIRE_LEVELS) api_wire_put_levels(b, &a->m);
	else api_wire_put_model(b, &a->m);
}

static void do_job(const struct api_sbx_request *rq, const uint8_t *in, struct answer *a)
{
	a->kind = rq->kind == API_WIRE_IMAGE || rq->kind == API_WIRE_LEVELS ? (enum api_wire_kind)rq->kind : API_WIRE_MODEL;
	if (a->kind == API_WIRE_IMAGE) {
		a->st = API_WIRE_OK;
		if (api_image_decode(in, rq->input_len, rq->max_pixels, &a->px, &a->w, &a->h, a->err, sizeof a->err) != API_OK)
			a->st = strstr(a->err, "out of memory") ? API_WIRE_OVER_MEMORY : API_WIRE_BAD_INPUT;
		return;
	}
	struct api_arena *arena = api_arena_create();   /* never destroyed: the process ends after the reply */
	size_t bytes;
	if (a->kind == API_WIRE_LEVELS) {
		/* The meshes that want levels, as a model (api_sandbox_build_levels); the input stays
		 * until the process ends. */
		a->st = API_WIRE_BAD_INPUT;
		if (!arena) a->st = API_WIRE_OVER_MEMORY, snprintf(a->err, sizeof a->err, "out of memory");
		else if (api_wire_decode_model(in, rq->input_len, API_WIRE_IN_PLACE, arena, 1, &a->m, &bytes, a->err,
		                               sizeof a->err) == API_OK)
			a->st = API_WIRE_OK;
		/* (api_wire_decode_model has set every mesh's bounds) */
		if (a->st == API_WIRE_OK) api_model_build_level(&a->m, rq->output_side, arena, &bytes);
		return;
	}
	/* The model's bytes, then the files it refers to (api_sbx_bundle_encode). */
	struct api_model_file *files = calloc(rq->file_count + 1u, sizeof *files);
	a->st = API_WIRE_OVER_MEMORY;
	if (!arena || !files) snprintf(a->err, sizeof a->err, "out of memory");
	else if (api_sbx_bundle_decode(in, rq->input_len, rq->model_len, rq->file_count, files) < 0)
		a->st = API_WIRE_BAD_INPUT, snprintf(a->err, sizeof a->err, "the importer's input is inconsistent");
	else a->st = api_model_import_files(in, rq->model_len, files, rq->file_count, (enum api_model_format)rq->format,
	                                    rq->output_side, arena, &a->m, &bytes, a->err, sizeof a->err);
	/* Closedness and the request's one level of detail, here under the import's limits. */
	if (a->st == API_WIRE_OK) api_model_finish_import(&a->m, rq->output_side, arena, &bytes);
}

/* The answer into the daemon's reply file (API_SBX_REPLY_FD, a memfd), written as it is
 * serialised (the kernel copies it there from the arrays where they are: no buffer of the
 * whole reply, no fresh pages mapped here), and its length (u64) on the data socket. A reply
 * longer than the file may grow (RLIMIT_FSIZE: the reply size the daemon allows) fails its
 * write (SIGXFSZ is ignored): over the memory limit. Exits on failure. */
static void send_answer(const struct answer *a)
{
	struct api_wire_buf out = {.fd = API_SBX_REPLY_FD};
	emit(a, &out);
	uint64_t n = out.len;
	if (api_wire_flush(&out) != 0) _exit(API_SBX_EXIT_OOM);
	if (!io_all(API_SBX_DATA_FD, &n, sizeof n, true)) _exit(API_SBX_EXIT_IO);
}

static void child_main(int data_fd, int reply_fd, const struct api_sbx_request *rq)
{
	if (prctl(PR_SET_PDEATHSIG, SIGKILL) || getppid() == 1) _exit(API_SBX_EXIT_SETUP);
	/* Both above the fds they go to first, so that neither dup2 closes the other. */
	data_fd = fcntl(data_fd, F_DUPFD, API_SBX_REPLY_FD + 1);
	reply_fd = fcntl(reply_fd, F_DUPFD, API_SBX_REPLY_FD + 1);
	if (data_fd < 0 || reply_fd < 0 || dup2(data_fd, API_SBX_DATA_FD) < 0 || dup2(reply_fd, API_SBX_REPLY_FD) < 0)
		_exit(API_SBX_EXIT_SETUP);
	/* stdin/stdout/stderr are the daemon's: a compromised child must not write into its log. */
	int dn = open("/dev/null", O_RDWR | O_CLOEXEC);
	if (dn < 0 || dup2(dn, 0) < 0 || dup2(dn, 1) < 0 || dup2(dn, 2) < 0) _exit(API_SBX_EXIT_SETUP);
	close_range(API_SBX_REPLY_FD + 1, ~0u, 0);
	sigset_t none;
	sigemptyset(&none);
	sigprocmask(SIG_SETMASK, &none, NULL);
	struct sigaction sa = {.sa_handler = on_fatal, .sa_flags = SA_RESETHAND};
	static const int fatal[] = {SIGSEGV, SIGBUS, SIGABRT, SIGILL, SIGFPE};
	for (size_t i = 0; i < sizeof fatal / sizeof fatal[0]; i++) sigaction(fatal[i], &sa, NULL);
	signal(SIGXFSZ, SIG_IGN);   /* a reply past RLIMIT_FSIZE: its write fails (EFBIG) */
	prctl(PR_SET_DUMPABLE, 0);
	/* jansson (the glTF pre-check) seeds its hash from /dev/urandom on first use: done here,
	 * while files can still be opened, and fresh in every child. */
	json_object_seed(0);
	/* The import's threads (api/workers.h), the daemon's share of the cores: started before
	 * the limits and the filter, which then cover them (no thread can be made after). One
	 * malloc arena for them all: a thread's own arena would reserve 64 MiB of RLIMIT_AS. */
	if (rq->threads > 1) {
		mallopt(M_ARENA_MAX, 1);
		api_workers_start(rq->threads);
	}
	if (set_limits(rq) || prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) || apply_filter()) _exit(API_SBX_EXIT_SETUP);

	uint8_t *in = malloc(rq->input_len ? rq->input_len : 1);
	if (!in) _exit(API_SBX_EXIT_OOM);
	if (!io_all(API_SBX_DATA_FD, in, rq->input_len, false)) _exit(API_SBX_EXIT_IO);
	struct answer a;
	memset(&a, 0, sizeof a);
	do_job(rq, in, &a);
	send_answer(&a);
	_exit(0);
}

/* ---- the fork server ---- */

struct kid {
	pid_t pid;
	int status_fd;
	struct timespec deadline;
	bool timed_out;
};

static struct kid kids[API_SBX_MAX_CHILDREN];
static unsigned nkids;

static void send_status(int fd, uint32_t how, int32_t code)
{
	struct api_sbx_status st = {API_SBX_MAGIC, how, code, 0};
	io_all(fd, &st, sizeof st, true); /* the daemon may have given up: nothing to do then */
	close(fd);
}

static void reap(void)
{
	int ws;
	pid_t pid;
	while ((pid = waitpid(-1, &ws, WNOHANG)) > 0) {
		for (unsigned i = 0; i < nkids; i++) {
			if (kids[i].pid != pid) continue;
			if (kids[i].timed_out) send_status(kids[i].status_fd, API_SBX_TIMED_OUT, SIGKILL);
			else if (WIFSIGNALED(ws)) send_status(kids[i].status_fd, API_SBX_SIGNALED, WTERMSIG(ws));
			else send_status(kids[i].status_fd, API_SBX_EXITED, WEXITSTATUS(ws));
			kids[i] = kids[--nkids];
			break;
		}
	}
}

static long ms_until(const struct timespec *t)
{
	struct timespec now;
	clock_gettime(CLOCK_MONOTONIC, &now);
	long ms = (t->tv_sec - now.tv_sec) * 1000 + (t->tv_nsec - now.tv_nsec) / 1000000;
	return ms < 0 ? 0 : ms;
}

/* Kills the overdue; returns the milliseconds to the next deadline (-1: none). */
static long police(void)
{
	long next = -1;
	for (unsigned i = 0; i < nkids; i++) {
		if (kids[i].timed_out) continue;
		long ms = ms_until(&kids[i].deadline);
		if (ms == 0) {
			kill(kids[i].pid, SIGKILL);
			kids[i].timed_out = true;
		} else if (next < 0 || ms < next) {
			next = ms;
		}
	}
	return next;
}

/* One request from the control socket with its fds {data socket, status pipe, reply memfd}:
 * 1 handled, 0 EOF, -1 error. */
static int take_request(int ctl)
{
	struct api_sbx_request rq;
	union { struct cmsghdr h; char buf[CMSG_SPACE(3 * sizeof(int))]; } cm;
	struct iovec iov = {&rq, sizeof rq};
	struct msghdr msg = {.msg_iov = &iov, .msg_iovlen = 1, .msg_control = cm.buf, .msg_controllen = sizeof cm.buf};
	ssize_t n = recvmsg(ctl, &msg, MSG_CMSG_CLOEXEC);
	if (n == 0) return 0;
	if (n < 0) return errno == EINTR || errno == EAGAIN ? 1 : -1;
	int fds[3] = {-1, -1, -1}, nfds = 0;
	for (struct cmsghdr *c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c))
		if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_RIGHTS) {
			int k = (int)((c->cmsg_len - CMSG_LEN(0)) / sizeof(int));
			for (int i = 0; i < k; i++) {
				int fd;
				memcpy(&fd, CMSG_DATA(c) + i * sizeof(int), sizeof fd);
				if (nfds < 3) fds[nfds++] = fd; else close(fd);
			}
		}
	if (nfds != 3 || n != (ssize_t)sizeof rq || rq.magic != API_SBX_MAGIC || (msg.msg_flags & MSG_CTRUNC)) {
		if (nfds >= 2) send_status(fds[1], API_SBX_REFUSED, 0);
		if (nfds >= 1) close(fds[0]);
		if (nfds == 3) close(fds[2]);
		return 1;
	}
	pid_t pid = nkids < API_SBX_MAX_CHILDREN ? fork() : -1;
	if (pid == 0) {
		close(ctl);
		close(fds[1]);
		child_main(fds[0], fds[2], &rq);
	}
	close(fds[0]);
	close(fds[2]);
	if (pid < 0) {
		send_status(fds[1], API_SBX_REFUSED, errno);
		return 1;
	}
	struct kid *k = &kids[nkids++];
	k->pid = pid;
	k->status_fd = fds[1];
	k->timed_out = false;
	clock_gettime(CLOCK_MONOTONIC, &k->deadline);
	k->deadline.tv_sec += rq.timeout_ms / 1000;
	k->deadline.tv_nsec += (long)(rq.timeout_ms % 1000) * 1000000;
	if (k->deadline.tv_nsec >= 1000000000) k->deadline.tv_sec++, k->deadline.tv_nsec -= 1000000000;
	return 1;
}

static void on_sigchld(int sig)
{
	(void)sig; /* only interrupts ppoll() */
}

int api_sandbox_helper_main(int argc, char **argv)
{
	if (argc != 2 || strcmp(argv[1], "--fork-server")) {
		fprintf(stderr, "usage: umbra-import --fork-server   (started by umbrad / umbra-render with its control "
		                "socket on fd %d; see api/sandbox.h)\n", API_SBX_CTL_FD);
		return 2;
	}
	int ctl = API_SBX_CTL_FD;
	int type = 0;
	socklen_t tl = sizeof type;
	if (getsockopt(ctl, SOL_SOCKET, SO_TYPE, &type, &tl) || type != SOCK_SEQPACKET) {
		fprintf(stderr, "umbra-import: fd %d is not the control socket\n", ctl);
		return 2;
	}
	close_range(API_SBX_CTL_FD + 1, ~0u, 0);
	signal(SIGPIPE, SIG_IGN);
	/* A SIGTERM to the whole process group (systemd's stop) must not kill imports the daemon is
	 * still draining: the fork server ends when the daemon does (EOF on the control socket). */
	signal(SIGTERM, SIG_IGN);
	signal(SIGINT, SIG_IGN);
	sigset_t chld, wait_mask;
	sigemptyset(&chld);
	sigaddset(&chld, SIGCHLD);
	sigprocmask(SIG_BLOCK, &chld, &wait_mask);
	sigdelset(&wait_mask, SIGCHLD);
	struct sigaction sa = {.sa_handler = on_sigchld, .sa_flags = SA_NOCLDSTOP};
	sigaction(SIGCHLD, &sa, NULL);
	for (;;) {
		reap();
		long ms = police();
		struct timespec ts = {ms / 1000, (ms % 1000) * 1000000};
		struct pollfd p = {ctl, POLLIN, 0};
		int r = ppoll(&p, 1, ms < 0 ? NULL : &ts, &wait_mask);
		if (r < 0 && errno != EINTR) break;
		if (r > 0 && (p.revents & (POLLIN | POLLHUP | POLLERR)) && take_request(ctl) <= 0) break;
	}
	for (unsigned i = 0; i < nkids; i++) kill(kids[i].pid, SIGKILL);
	while (nkids) {
		int ws;
		pid_t pid = waitpid(-1, &ws, 0);
		if (pid < 0) break;
		for (unsigned i = 0; i < nkids; i++)
			if (kids[i].pid == pid) { close(kids[i].status_fd); kids[i] = kids[--nkids]; break; }
	}
	return 0;
}
