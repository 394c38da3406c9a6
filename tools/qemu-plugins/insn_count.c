/* A QEMU TCG plugin that counts the guest instructions a program executes and prints the total at exit
 * ("insns N", in QEMU's log: -d plugin, stderr unless -D FILE). For tools/bench-camera: detection cost under qemu-user as instructions per frame.
 *
 * Debian ships QEMU's plugin-capable user-mode emulator (qemu-user, dynamically linked; the static qemu-user-static
 * cannot load plugins) but not the plugin header, so the few entry points used here are declared as QEMU 7.2's
 * include/qemu/qemu-plugin.h declares them (plugin API version 1). Build: cc -shared -fPIC -O2 -o libinsn_count.so
 * insn_count.c; run: qemu-aarch64 -plugin ./libinsn_count.so PROGRAM ARGS. */
#include <inttypes.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

typedef uint64_t qemu_plugin_id_t;
typedef struct qemu_info_t qemu_info_t;
struct qemu_plugin_tb;
enum qemu_plugin_op { QEMU_PLUGIN_INLINE_ADD_U64 };
typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t id, struct qemu_plugin_tb* tb);
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t id, void* userdata);

void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb* tb);
void qemu_plugin_register_vcpu_tb_exec_inline(struct qemu_plugin_tb* tb, enum qemu_plugin_op op, void* ptr,
                                              uint64_t imm);
void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb, void* userdata);
void qemu_plugin_outs(const char* string);

#define EXPORT __attribute__((visibility("default")))

EXPORT int qemu_plugin_version = 1;

/* One counter for every vCPU: the benchmark's detector runs on one thread (threads = 1), so the inline adds do not
 * race. A multi-threaded guest would undercount slightly. */
static uint64_t insns;

/* At translation: every execution of this block adds its instruction count (an inline add, no callback). */
static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb* tb) {
  (void)id;
  qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &insns, qemu_plugin_tb_n_insns(tb));
}

static void on_guest_exit(qemu_plugin_id_t id, void* userdata) {
  (void)id;
  (void)userdata;
  char line[64];
  snprintf(line, sizeof line, "insns %" PRIu64 "\n", insns);
  qemu_plugin_outs(line);
}

EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t* info, int argc, char** argv) {
  (void)info;
  (void)argc;
  (void)argv;
  qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
  qemu_plugin_register_atexit_cb(id, on_guest_exit, NULL);
  return 0;
}
