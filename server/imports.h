/*
 * umbrad import threads: sandboxed model imports run on threads of their own (--import-slots),
 * never on the --workers threads that take requests from the queue.
 *
 * Why: an import ran on the worker thread that parsed the request, for up to
 * --import-timeout-ms. Four endless PLYs on two workers answered 422 at 10, 10, 20 and 20 s,
 * and the daemon answered one other render in those 20 s: imports held every worker. Now a
 * worker whose parse reaches the import of a model the cache lacks stops there (api.h
 * api_import_gate) and parks the request; an import thread takes it, parses it again with the
 * import allowed, and renders and answers it like a worker. A parked request holds no thread.
 *
 * Share: an import thread that comes free takes the parked request of the client address
 * (IPv4, or an IPv6 /64) with the fewest requests taken and not yet answered, first parked
 * among equals; a client alone takes every slot, and another client's request gets the next
 * slot that frees.
 *
 * Overlap (issue 28): at most `slots` imports run at once, but there are twice as many import
 * threads: a thread whose import is done (srv_imports_imported) gives its slot back before it
 * waits for the device and renders, so the next model is imported while this one renders. On a
 * CPU device one render at a time already takes every core lavapipe has (server/gate.h), and an
 * import is one child process on one core.
 *
 * Levels of a cached model at another size and texture decodes are not gated: each is bounded
 * by the import limits and happens once per model and size.
 *
 * Threading: every function is safe from any thread.
 */
#ifndef UMBRA_SRV_IMPORTS_H
#define UMBRA_SRV_IMPORTS_H

#include <stdbool.h>
#include <stdint.h>
#include <sys/socket.h>

struct srv_request;
struct srv_imports;

struct srv_imports *srv_imports_create(unsigned slots);
void srv_imports_destroy(struct srv_imports *im);   /* NULL-safe; nothing may be parked */
/* Parks req for an import thread (req->client says whose). */
void srv_imports_park(struct srv_imports *im, struct srv_request *req);
/* An import thread: waits for a parked request and counts it running for its client; NULL once
 * closed with none parked. srv_imports_done() when it is answered. */
struct srv_request *srv_imports_take(struct srv_imports *im);
/* The taken request's parse (its import) is over, however it ended: its slot is free for the
 * next import. Once per take, before srv_imports_done. */
void srv_imports_imported(struct srv_imports *im);
void srv_imports_done(struct srv_imports *im, uint64_t client);
/* Import threads for `slots` import slots (0: 1). */
unsigned srv_imports_threads(unsigned slots);
/* No more parking after this: the import threads drain what is parked and end. */
void srv_imports_close(struct srv_imports *im);
/* Imports running, and requests parked, now. */
void srv_imports_counts(struct srv_imports *im, unsigned *running, unsigned *parked);

/* The client key of a peer address: an IPv4 address, or an IPv6 /64 (one host's addresses). */
uint64_t srv_client_key(const struct sockaddr *sa);

#endif
