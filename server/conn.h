/*
 * umbrad connections (conn.c): listen address, descriptor budget, header timeout, framing.
 *
 * Usage (http.c): srv_conn_prepare() and srv_conn_listen_addr() before MHD_start_daemon;
 * srv_conn_notify as MHD_OPTION_NOTIFY_CONNECTION with the struct srv_config as closure;
 * srv_conn_request_begins() and srv_conn_framing_error() on the first call of the access
 * handler for each request. Threading: the last three run on libmicrohttpd's polling thread.
 * Nothing here allocates or owns anything.
 */
#ifndef UMBRA_CONN_H
#define UMBRA_CONN_H

#include <microhttpd.h>
#include <sys/socket.h>

#include "srv.h"

/* Raises the open-file soft limit to the hard one and lowers cfg->max_connections (with a
 * warning) when the descriptors still cannot hold that many connections. */
void srv_conn_prepare(struct srv_config *cfg);

/* Parses ADDR:PORT ("[::1]:8080" for IPv6). 0, or -1 with the reason logged. */
int srv_conn_listen_addr(const char *listen, struct sockaddr_storage *ss, socklen_t *len);

/* MHD_NotifyConnectionCallback; cls is the const struct srv_config. New connections get
 * --header-timeout until their first request head is complete. */
void srv_conn_notify(void *cls, struct MHD_Connection *conn, void **socket_ctx,
                     enum MHD_ConnectionNotificationCode code);

/* A request head is complete: the connection's timeout becomes --idle-timeout. */
void srv_conn_request_begins(const struct srv_config *cfg, struct MHD_Connection *conn);

/* Why the request's framing headers are unacceptable, with *status (400 or 501), or NULL
 * when they are fine. The answer must close the connection: its body boundary is unknown. */
const char *srv_conn_framing_error(struct MHD_Connection *conn, const char *version, int *status);

#endif
