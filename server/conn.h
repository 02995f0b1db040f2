/*
 * umbrad connections (conn.c): listen address, descriptor budget, share per address range
 * (server/ranges.h), header timeout, framing.
 *
 * Usage (http.c): srv_conn_prepare(), srv_conn_share_start() and srv_conn_listen_addr() before
 * MHD_start_daemon; srv_conn_accept as its accept policy callback and srv_conn_notify as
 * MHD_OPTION_NOTIFY_CONNECTION, both with the struct srv_server as closure;
 * srv_conn_request_begins() and srv_conn_framing_error() on the first call of the access
 * handler for each request; srv_conn_share_stop() after MHD_stop_daemon. Threading: the
 * callbacks run on libmicrohttpd's polling thread. The range table (s->ranges) is the one thing
 * allocated here: srv_conn_share_start() creates it, srv_conn_share_stop() frees it.
 */
#ifndef UMBRA_CONN_H
#define UMBRA_CONN_H

#include <microhttpd.h>
#include <sys/socket.h>

#include "srv.h"

/* Raises the open-file soft limit to the hard one and lowers cfg->max_connections (with a
 * warning) when the descriptors still cannot hold that many connections. */
void srv_conn_prepare(struct srv_config *cfg);

/* Creates s->ranges with --max-connections-per-range, resolving its default (a quarter of
 * --max-connections as srv_conn_prepare() left it, at least 1). 0, or -1 (logged). */
int srv_conn_share_start(struct srv_server *s);
void srv_conn_share_stop(struct srv_server *s);

/* MHD_AcceptPolicyCallback; cls is the struct srv_server. Refuses (closes unanswered) a new
 * connection whose address range holds its share already; libmicrohttpd calls it only after
 * --max-connections and --max-connections-per-ip let the connection through. */
enum MHD_Result srv_conn_accept(void *cls, const struct sockaddr *addr, socklen_t len);

/* Parses ADDR:PORT ("[::1]:8080" for IPv6). 0, or -1 with the reason logged. */
int srv_conn_listen_addr(const char *listen, struct sockaddr_storage *ss, socklen_t *len);

/* MHD_NotifyConnectionCallback; cls is the struct srv_server. New connections get
 * --header-timeout until their first request head is complete, and count for their range
 * until they close. */
void srv_conn_notify(void *cls, struct MHD_Connection *conn, void **socket_ctx,
                     enum MHD_ConnectionNotificationCode code);

/* A request head is complete: the connection's timeout becomes --idle-timeout. */
void srv_conn_request_begins(const struct srv_config *cfg, struct MHD_Connection *conn);

/* Why the request's framing headers are unacceptable, with *status (400 or 501), or NULL
 * when they are fine. The answer must close the connection: its body boundary is unknown. */
const char *srv_conn_framing_error(struct MHD_Connection *conn, const char *version, int *status);

#endif
