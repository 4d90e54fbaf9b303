/* SIGINT / SIGTERM -> nav_sim_request_cancel (an atomic store: async-signal-safe). */
#define _POSIX_C_SOURCE 200809L
#include "interrupt.h"

#include <signal.h>
#include <stddef.h>
#include <string.h>

static nav_sim *volatile g_sim;
static volatile sig_atomic_t g_signal;

static void on_signal(int sig) {
  g_signal = sig;
  nav_sim *sim = g_sim;
  if (sim) nav_sim_request_cancel(sim);
}

void navsim_interrupt_arm(nav_sim *sim) {
  g_sim = sim;
  g_signal = 0;
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
}

void navsim_interrupt_disarm(void) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = SIG_DFL;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  g_sim = NULL;
}

void navsim_interrupt_detach(void) { g_sim = NULL; }

int navsim_interrupted(void) { return (int)g_signal; }
