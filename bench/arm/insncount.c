/* insncount: a QEMU TCG plugin that counts the guest instructions a program executes.
 *
 * Written for qemu-user 7.2 (Debian 12's qemu-user package; the static qemu-*-static binaries
 * cannot load plugins). Debian ships neither QEMU's example plugins nor qemu-plugin.h, so the
 * few declarations of QEMU's stable plugin API (docs/devel/tcg-plugins.rst, API version 1)
 * that this file uses are written out below.
 *
 * How it counts: at translation time every translation block (TB) gets an execution
 * callback whose user data is the TB's instruction count; the callback adds it to a counter
 * of the executing vCPU (in qemu-user: of the guest thread), so threads never share a
 * counter. At exit the counters are summed. A TB left early by an exception or a signal is
 * counted whole (negligible for compute-bound code).
 *
 * Options (-plugin ./libinsncount.so,out=FILE): out=FILE appends one line
 * "insns=<total> threads=<vcpus seen>" to FILE (default: QEMU's log, i.e. stderr).
 * Build: bench/arm/build.sh (bench/arm/arm-cost.sh calls it).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stdbool.h>

/* ---- the subset of QEMU's plugin API used here (API version 1, QEMU 7.x) ---- */
typedef uint64_t qemu_plugin_id_t;
typedef struct {
  const char *target_name;
  struct { int min; int cur; } version;
  bool system_emulation;
  union { struct { int smp_vcpus; int max_vcpus; } system; };
} qemu_info_t;
struct qemu_plugin_tb;
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS, QEMU_PLUGIN_CB_R_REGS, QEMU_PLUGIN_CB_RW_REGS };
typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb *tb);
typedef void (*qemu_plugin_vcpu_udata_cb_t)(unsigned int vcpu_index, void *userdata);
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t id, void *userdata);
void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
void qemu_plugin_register_vcpu_tb_exec_cb(struct qemu_plugin_tb *tb, qemu_plugin_vcpu_udata_cb_t cb,
                                          enum qemu_plugin_cb_flags flags, void *userdata);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *tb);
void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb, void *userdata);
void qemu_plugin_outs(const char *string);
#define QEMU_PLUGIN_EXPORT __attribute__((visibility("default")))
/* ---------------------------------------------------------------------------- */

QEMU_PLUGIN_EXPORT int qemu_plugin_version = 1;

#define SLOTS 4096
struct slot { uint64_t n; char pad[56]; };   /* one cache line per vCPU: no false sharing */
static struct slot counts[SLOTS];
static uint64_t overflow;                     /* vCPU index >= SLOTS: shared, atomic */
static unsigned int max_vcpu;
static char *out_path;

static void on_tb_exec(unsigned int vcpu, void *udata) {
  const uint64_t n = (uint64_t)(uintptr_t)udata;
  if (vcpu < SLOTS) {
    counts[vcpu].n += n;
    if (vcpu > __atomic_load_n(&max_vcpu, __ATOMIC_RELAXED)) __atomic_store_n(&max_vcpu, vcpu, __ATOMIC_RELAXED);
  } else {
    __atomic_fetch_add(&overflow, n, __ATOMIC_RELAXED);
  }
}

static void on_tb_trans(qemu_plugin_id_t id, struct qemu_plugin_tb *tb) {
  (void)id;
  qemu_plugin_register_vcpu_tb_exec_cb(tb, on_tb_exec, QEMU_PLUGIN_CB_NO_REGS,
                                       (void *)(uintptr_t)qemu_plugin_tb_n_insns(tb));
}

static void on_exit_(qemu_plugin_id_t id, void *p) {
  (void)id, (void)p;
  uint64_t total = __atomic_load_n(&overflow, __ATOMIC_RELAXED);
  unsigned int threads = 0;
  for (int i = 0; i < SLOTS; ++i) {
    total += counts[i].n;
    if (counts[i].n) ++threads;
  }
  char line[128];
  snprintf(line, sizeof line, "insns=%llu threads=%u\n", (unsigned long long)total, threads);
  FILE *f = out_path ? fopen(out_path, "a") : NULL;
  if (f) {
    fputs(line, f);
    fclose(f);
  } else {
    qemu_plugin_outs(line);
  }
}

QEMU_PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv) {
  (void)info;
  for (int i = 0; i < argc; ++i) {
    if (strncmp(argv[i], "out=", 4) == 0) {
      out_path = strdup(argv[i] + 4);
    } else {
      fprintf(stderr, "insncount: unknown option '%s' (only out=FILE)\n", argv[i]);
      return -1;
    }
  }
  qemu_plugin_register_vcpu_tb_trans_cb(id, on_tb_trans);
  qemu_plugin_register_atexit_cb(id, on_exit_, NULL);
  return 0;
}
