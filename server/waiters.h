/* waiters.h - the long-poll of GET /jobs/{id}?wait=N: a request that must wait for a job
 * to finish is suspended (by the HTTP side: libmicrohttpd's suspend/resume, so no HTTP
 * thread is held) and resumed when the job reaches a final status, its deadline passes,
 * or its client hangs up (libmicrohttpd does not watch a suspended connection: the
 * registry's thread polls their sockets, so that an abandoned wait gives back its place
 * in the connection limits at once).
 *
 * Locking: one mutex guards the list; suspend and resume calls are made under it so that
 * a connection is never resumed before it was suspended. */
#ifndef GRAINPACKD_WAITERS_H
#define GRAINPACKD_WAITERS_H

typedef struct gp_waiters gp_waiters;
typedef struct gp_waiter gp_waiter; /* one waiting request; owned by the registry */

/* How the HTTP side holds a waiting request's connection (gp_request.conn) and lets it go
 * on: http.c's gp_http_suspender. socket gives the connection's socket, which the
 * registry polls for the client's hang-up while the request is suspended (-1: none, the
 * wait then ends only by its job or its deadline). */
typedef struct gp_suspender {
    void (*suspend)(void *conn);
    void (*resume)(void *conn);
    int (*socket)(void *conn);
} gp_suspender;

/* Starts the registry and its deadline thread; `how` (not copied) must outlive it.
 * Returns 0 or GP_ENOMEM. */
int gp_waiters_start(gp_waiters **out, const gp_suspender *how);

/* Resumes every waiting request (they answer with the job as it is), refuses new waits
 * and stops the thread. Call before stopping the HTTP daemon; gp_waiters_free after. */
void gp_waiters_stop(gp_waiters *w);
void gp_waiters_free(gp_waiters *w);

/* Registers a request for job_id until `deadline` (monotonic seconds). Returns the entry
 * or NULL when out of memory or stopping. The caller then checks the job and either
 * calls gp_waiters_cancel (it is already final) or gp_waiters_suspend. */
gp_waiter *gp_waiters_add(gp_waiters *w, void *conn, const char *job_id, double deadline);

/* Suspends the connection unless the entry was woken meanwhile (or the registry is
 * stopping). Returns 1 when suspended (the handler returns and is called again once
 * resumed), 0 when not (the entry is freed: answer now). Either way the caller must not
 * touch the entry again. */
int gp_waiters_suspend(gp_waiters *w, gp_waiter *entry);

/* Removes an entry that was not suspended. */
void gp_waiters_cancel(gp_waiters *w, gp_waiter *entry);

/* The job reached a final status: resume its waiters. */
void gp_waiters_wake(gp_waiters *w, const char *job_id);

/* Waits ended so far because the client closed its connection. */
unsigned long gp_waiters_hung_up(gp_waiters *w);

#endif
