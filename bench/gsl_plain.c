/* bodypoint benchmark: GSL as its own users drive it, with nothing of bodypoint in the loop.
 *
 * A stand-alone C program: the body-point's equations of motion (docs/physics.md, "Equations of
 * motion") as a plain C right-hand side, integrated by GSL's driver (gsl_odeiv2_driver_apply) with the
 * standard control eps_abs = eps_rel = tol, exactly as bodypoint's gsl-* peers set it. bench/gsl_peer.cpp
 * calls its integration (gsl_plain_run, compiled with GSL_PLAIN_LIBRARY) beside bodypoint's gsl-rk8pd /
 * gsl-rkf45 in one process, interleaved, and checks that the peer costs no more than it at equal force
 * evaluations; built alone it is the command below, for checks by hand.
 *
 *   gsl_plain STEPPER TOL T_END REPEATS m B J  Rx Ry Rz vx vy vz wx wy wz  [cx cy cz A]...
 *
 * STEPPER is rk8pd or rkf45. Prints one line per repeat: force_evals wall_s cpu_s Rx Ry Rz vx vy vz,
 * wall and this thread's CPU time per integration (driver_apply alone), each repeat a batch of identical
 * integrations lasting at least MIN_REPEAT_S (a few-microsecond run is not timed by one clock reading);
 * the warm-up, which also sizes the batch, is not printed.
 */
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAX_CENTRES 64

typedef struct {
  double cJ, cBB, cB, cmB; /* J/D, B^2/D, B/D, m B/D with D = m J - B^2 */
  int n;
  double c[MAX_CENTRES][4]; /* cx, cy, cz, A */
  long evals;
} Body;

static int rhs(double t, const double y[], double f[], void* params) {
  Body* b = (Body*)params;
  double F[3] = {0.0, 0.0, 0.0};
  (void)t;
  ++b->evals;
  for (int k = 0; k < b->n; ++k) {
    const double dx = y[0] - b->c[k][0], dy = y[1] - b->c[k][1], dz = y[2] - b->c[k][2];
    const double r2 = dx * dx + dy * dy + dz * dz;
    const double s = -b->c[k][3] / (r2 * sqrt(r2)); /* F = -A (R - c) / |R - c|^3 */
    F[0] += s * dx;
    F[1] += s * dy;
    F[2] += s * dz;
  }
  const double wxv[3] = {y[7] * y[5] - y[8] * y[4], y[8] * y[3] - y[6] * y[5], y[6] * y[4] - y[7] * y[3]};
  for (int i = 0; i < 3; ++i) {
    f[i] = y[3 + i];
    f[3 + i] = b->cJ * F[i] - b->cBB * wxv[i];
    f[6 + i] = -b->cB * F[i] + b->cmB * wxv[i];
  }
  return GSL_SUCCESS;
}


/* One integration from y0 to t_end with the driver d (reset to the first trial step 1e-3); returns the
 * driver's status, y the final state. */
static int integrate(gsl_odeiv2_driver* d, double t_end, const double y0[9], double y[9]) {
  double t = 0.0;
  memcpy(y, y0, 9 * sizeof(double));
  gsl_odeiv2_driver_reset_hstart(d, 1e-3);
  const int status = gsl_odeiv2_driver_apply(d, &t, t_end, y);
  if (status != GSL_SUCCESS) fprintf(stderr, "gsl_plain: the driver failed at t = %.17g: %s\n", t, gsl_strerror(status));
  return status;
}

/* One integration from y0 (m, B, J; n centres as cx, cy, cz, A) to t_end with GSL's rk8pd or rkf45 at
 * tol, as a C user writes it: allocate the driver, apply it, free it. Returns the force evaluations
 * (-1: the driver failed), y the final state. */
long gsl_plain_run(int rk8pd, double tol, double t_end, double m, double B, double J, const double y0[9],
                   int n, const double (*centres)[4], double y[9]);
long gsl_plain_run(int rk8pd, double tol, double t_end, double m, double B, double J, const double y0[9],
                   int n, const double (*centres)[4], double y[9]) {
  const double D = m * J - B * B;
  Body body = {J / D, B * B / D, B / D, m * B / D, n, {{0}}, 0};
  for (int k = 0; k < n && k < MAX_CENTRES; ++k) memcpy(body.c[k], centres[k], sizeof body.c[k]);
  gsl_odeiv2_system sys = {rhs, NULL, 9, &body};
  gsl_odeiv2_driver* d =
      gsl_odeiv2_driver_alloc_y_new(&sys, rk8pd ? gsl_odeiv2_step_rk8pd : gsl_odeiv2_step_rkf45, 1e-3, tol, tol);
  const int status = integrate(d, t_end, y0, y);
  gsl_odeiv2_driver_free(d);
  return status == GSL_SUCCESS ? body.evals : -1;
}

#ifndef GSL_PLAIN_LIBRARY
#define MIN_REPEAT_S 2e-3

static double seconds(clockid_t clock) {
  struct timespec ts;
  clock_gettime(clock, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double number(const char* s, const char* what) {
  char* end = NULL;
  const double x = strtod(s, &end);
  if (end == s || *end != '\0' || !isfinite(x)) {
    fprintf(stderr, "gsl_plain: %s is not a finite number: '%s'\n", what, s);
    exit(2);
  }
  return x;
}

int main(int argc, char** argv) {
  if (argc < 17 || (argc - 17) % 4 != 0 || (argc - 17) / 4 > MAX_CENTRES) {
    fprintf(stderr, "usage: gsl_plain rk8pd|rkf45 TOL T_END REPEATS m B J Rx Ry Rz vx vy vz wx wy wz [cx cy cz A]...\n");
    return 2;
  }
  const gsl_odeiv2_step_type* type = NULL;
  if (strcmp(argv[1], "rk8pd") == 0) type = gsl_odeiv2_step_rk8pd;
  else if (strcmp(argv[1], "rkf45") == 0) type = gsl_odeiv2_step_rkf45;
  else {
    fprintf(stderr, "gsl_plain: stepper must be rk8pd or rkf45, got '%s'\n", argv[1]);
    return 2;
  }
  const double tol = number(argv[2], "TOL"), t_end = number(argv[3], "T_END");
  const long repeats = (long)number(argv[4], "REPEATS");
  const double m = number(argv[5], "m"), B = number(argv[6], "B"), J = number(argv[7], "J");
  const double D = m * J - B * B;
  if (!(tol > 0.0) || !(t_end > 0.0) || repeats < 1 || !(D > 0.0)) {
    fprintf(stderr, "gsl_plain: need TOL > 0, T_END > 0, REPEATS >= 1 and m J - B^2 > 0\n");
    return 2;
  }
  Body body = {J / D, B * B / D, B / D, m * B / D, (argc - 17) / 4, {{0}}, 0};
  double y0[9];
  for (int i = 0; i < 9; ++i) y0[i] = number(argv[8 + i], "the state");
  for (int k = 0; k < body.n; ++k)
    for (int i = 0; i < 4; ++i) body.c[k][i] = number(argv[17 + 4 * k + i], "a centre");
  gsl_odeiv2_system sys = {rhs, NULL, 9, &body};
  gsl_odeiv2_driver* d = gsl_odeiv2_driver_alloc_y_new(&sys, type, 1e-3, tol, tol);
  double y[9];
  /* Warm-up, and the batch size: integrations per repeat lasting at least MIN_REPEAT_S. */
  const double w0 = seconds(CLOCK_MONOTONIC);
  if (integrate(d, t_end, y0, y) != GSL_SUCCESS) return 1;
  const double one = seconds(CLOCK_MONOTONIC) - w0;
  const long batch = one >= MIN_REPEAT_S ? 1 : (long)ceil(MIN_REPEAT_S / (one > 1e-9 ? one : 1e-9));
  for (long r = 0; r < repeats; ++r) {
    long evals = 0;
    const double w1 = seconds(CLOCK_MONOTONIC), c1 = seconds(CLOCK_THREAD_CPUTIME_ID);
    for (long k = 0; k < batch; ++k) {
      body.evals = 0;
      if (integrate(d, t_end, y0, y) != GSL_SUCCESS) return 1;
      evals = body.evals;
    }
    const double c2 = seconds(CLOCK_THREAD_CPUTIME_ID), w2 = seconds(CLOCK_MONOTONIC);
    printf("%ld %.9g %.9g %.17g %.17g %.17g %.17g %.17g %.17g\n", evals, (w2 - w1) / (double)batch,
           (c2 - c1) / (double)batch, y[0], y[1], y[2], y[3], y[4], y[5]);
  }
  gsl_odeiv2_driver_free(d);
  return 0;
}
#endif /* GSL_PLAIN_LIBRARY */
