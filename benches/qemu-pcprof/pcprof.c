/* QEMU TCG plugin (plugin API v1, e.g. Debian bookworm QEMU 7.2): counts executed guest instructions
   per address, for benches/mcu-profile.py. Same hand-written declarations as
   shared/tools/qemu-insncount. Writes "hex-address count" lines to $PCPROF_OUT (default
   pcprof.txt) at exit; addresses below 4 MiB (the mps2 flash) only. */
#include <stdint.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define EXPORT __attribute__((visibility("default")))
typedef uint64_t qemu_plugin_id_t;
struct qemu_plugin_tb; struct qemu_plugin_insn;
enum qemu_plugin_op { QEMU_PLUGIN_INLINE_ADD_U64 };
typedef void (*tb_trans_cb_t)(qemu_plugin_id_t, struct qemu_plugin_tb *);
typedef void (*udata_cb_t)(qemu_plugin_id_t, void *);
void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t, tb_trans_cb_t);
void qemu_plugin_register_vcpu_insn_exec_inline(struct qemu_plugin_insn *, enum qemu_plugin_op, void *, uint64_t);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *);
struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *, size_t);
uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *);
void qemu_plugin_register_atexit_cb(qemu_plugin_id_t, udata_cb_t, void *);
void qemu_plugin_outs(const char *);
EXPORT int qemu_plugin_version = 1;
#define N (4u<<20)
static uint64_t *counts;
/* The lowest address counted (PCPROF_BASE, hexadecimal; 0 when unset): 0x80000000 for
   qemu-system-riscv32's virt machine, whose RAM starts there. */
static uint64_t base;
static void trans(qemu_plugin_id_t id, struct qemu_plugin_tb *tb) {
    size_t n = qemu_plugin_tb_n_insns(tb);
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *in = qemu_plugin_tb_get_insn(tb, i);
        uint64_t a = qemu_plugin_insn_vaddr(in) - base;
        if (a < N) qemu_plugin_register_vcpu_insn_exec_inline(in, QEMU_PLUGIN_INLINE_ADD_U64, &counts[a/2], 1);
    }
}
static void at_exit(qemu_plugin_id_t id, void *p) {
    FILE *f = fopen(getenv("PCPROF_OUT") ? getenv("PCPROF_OUT") : "pcprof.txt", "w");
    for (uint32_t i = 0; i < N/2; i++) if (counts[i]) fprintf(f, "%llx %llu\n", (unsigned long long)(base + i*2), (unsigned long long)counts[i]);
    fclose(f);
}
EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const void *info, int argc, char **argv) {
    counts = calloc(N/2, sizeof(uint64_t));
    base = getenv("PCPROF_BASE") ? strtoull(getenv("PCPROF_BASE"), NULL, 16) : 0;
    qemu_plugin_register_vcpu_tb_trans_cb(id, trans);
    qemu_plugin_register_atexit_cb(id, at_exit, NULL);
    return 0;
}
