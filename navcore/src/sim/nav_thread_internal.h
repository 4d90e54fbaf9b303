/*
 * Thread creation for the Monte Carlo workers. C11 <threads.h> normally; POSIX threads when
 * NAV_USE_PTHREAD is defined, which the ThreadSanitizer build does: GCC 12's TSan intercepts
 * pthread_create but not glibc's thrd_create (which bypasses the interceptor), so TSan crashes
 * at thread start with C11 threads. Both paths run the same worker function.
 */
#ifndef NAV_THREAD_INTERNAL_H
#define NAV_THREAD_INTERNAL_H

#include <stdbool.h>

#ifdef NAV_USE_PTHREAD
#include <pthread.h>
typedef pthread_t nav_thread;
typedef struct nav_thread_call {
  int (*fn)(void *);
  void *arg;
} nav_thread_call;
static void *nav_thread_trampoline(void *p) {
  nav_thread_call *c = p;
  (void)c->fn(c->arg);
  return NULL;
}
/* @p call must outlive the thread. */
static inline bool nav_thread_start(nav_thread *t, nav_thread_call *call, int (*fn)(void *), void *arg) {
  call->fn = fn;
  call->arg = arg;
  return pthread_create(t, NULL, nav_thread_trampoline, call) == 0;
}
static inline void nav_thread_join(nav_thread t) { (void)pthread_join(t, NULL); }
typedef pthread_mutex_t nav_mutex;
static inline bool nav_mutex_init(nav_mutex *m) { return pthread_mutex_init(m, NULL) == 0; }
static inline void nav_mutex_lock(nav_mutex *m) { (void)pthread_mutex_lock(m); }
static inline void nav_mutex_unlock(nav_mutex *m) { (void)pthread_mutex_unlock(m); }
static inline void nav_mutex_destroy(nav_mutex *m) { (void)pthread_mutex_destroy(m); }
#else
#include <threads.h>
typedef thrd_t nav_thread;
typedef struct nav_thread_call {
  int unused;
} nav_thread_call;
static inline bool nav_thread_start(nav_thread *t, nav_thread_call *call, int (*fn)(void *), void *arg) {
  (void)call;
  return thrd_create(t, fn, arg) == thrd_success;
}
static inline void nav_thread_join(nav_thread t) { (void)thrd_join(t, NULL); }
typedef mtx_t nav_mutex;
static inline bool nav_mutex_init(nav_mutex *m) { return mtx_init(m, mtx_plain) == thrd_success; }
static inline void nav_mutex_lock(nav_mutex *m) { (void)mtx_lock(m); }
static inline void nav_mutex_unlock(nav_mutex *m) { (void)mtx_unlock(m); }
static inline void nav_mutex_destroy(nav_mutex *m) { mtx_destroy(m); }
#endif

#endif /* NAV_THREAD_INTERNAL_H */
