// Minimal Cortex-M start-up for the example firmware: vector table, reset handler (copy .data, zero .bss, enable
// the FPU, run static constructors, call main), fault handlers that stop the core. No C runtime start files
// (linked with -nostartfiles), so nothing of newlib's crt0 (exit, atexit, malloc'ed stdio) is pulled in.
#include <cstdint>

extern "C" {
// Symbols defined by the linker script (mps2_an500.ld).
extern std::uint32_t __data_load_start__;
extern std::uint32_t __data_start__;
extern std::uint32_t __data_end__;
extern std::uint32_t __bss_start__;
extern std::uint32_t __bss_end__;
extern std::uint32_t __stack_top__;
using InitFn = void (*)();
extern InitFn __init_array_start[];
extern InitFn __init_array_end[];

int main();
void Reset_Handler();
void Default_Handler();
// The firmware may define it (main.cpp does, to extend SysTick for its cost counters); otherwise it stops the core.
void SysTick_Handler() __attribute__((weak, alias("Default_Handler")));

// A pure virtual call can only be a bug; without this, libsupc++'s version drags in std::terminate and the
// exception machinery.
void __cxa_pure_virtual() { Default_Handler(); }
}

namespace {
// System Control Block: Coprocessor Access Control Register (ARMv7-M ARM, B3.2.20).
volatile std::uint32_t& cpacr() { return *reinterpret_cast<volatile std::uint32_t*>(0xE000ED88u); }
}  // namespace

extern "C" void Reset_Handler() {
  // The FPU must be on before any code touches a floating-point register (core and libm are built hard-float).
  cpacr() = cpacr() | (0xFu << 20);  // CP10 and CP11 full access
  __asm volatile("dsb\n\tisb" ::: "memory");

  for (std::uint32_t *src = &__data_load_start__, *dst = &__data_start__; dst < &__data_end__;) *dst++ = *src++;
  for (std::uint32_t* dst = &__bss_start__; dst < &__bss_end__;) *dst++ = 0;
  for (InitFn* f = __init_array_start; f < __init_array_end; ++f) (*f)();

  main();
  for (;;) __asm volatile("wfi");
}

extern "C" void Default_Handler() {
  for (;;) __asm volatile("bkpt 0");  // stops under a debugger; a locked-up core otherwise
}

// Cortex-M system exceptions (ARMv7-M: the same on M4 and M7); the device interrupts are not used by this example.
using Vector = void (*)();
__attribute__((section(".isr_vector"), used)) const Vector g_vectors[16] = {
    reinterpret_cast<Vector>(&__stack_top__),
    Reset_Handler,
    Default_Handler,  // NMI
    Default_Handler,  // HardFault
    Default_Handler,  // MemManage
    Default_Handler,  // BusFault
    Default_Handler,  // UsageFault
    nullptr, nullptr, nullptr, nullptr,
    Default_Handler,  // SVCall
    Default_Handler,  // DebugMonitor
    nullptr,
    Default_Handler,  // PendSV
    SysTick_Handler,
};
