/* Minimal Cortex-M4F start-up for QEMU mps2-an386: vector table, reset handler (FPU on, .data
   copied, .bss zeroed, C++ constructors run, main called), semihosting helpers. */
#include <stdint.h>
#include <stddef.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _stack_top;
extern void (*__init_array_start[])(void);
extern void (*__init_array_end[])(void);
int main(void);
void sh_exit(int status);

__attribute__((naked, noreturn)) void Reset_Handler(void)
{
    __asm volatile(
        "ldr r0, =0xE000ED88\n"      /* CPACR: full access to CP10/CP11 (the FPU) */
        "ldr r1, [r0]\n"
        "orr r1, r1, #(0xF << 20)\n"
        "str r1, [r0]\n"
        "dsb\n isb\n"
        "b reset_c\n");
}

__attribute__((used, noreturn)) void reset_c(void)
{
    uint32_t *src = &_sidata, *dst = &_sdata;
    while (dst < &_edata) *dst++ = *src++;
    for (dst = &_sbss; dst < &_ebss;) *dst++ = 0;
    for (void (**f)(void) = __init_array_start; f < __init_array_end; f++) (*f)();
    sh_exit(main());
    for (;;) {}
}

static void Fault_Handler(void) { sh_exit(3); }

__attribute__((section(".vectors"), used)) const void *const vectors[16] = {
    &_stack_top, (void *)Reset_Handler,
    (void *)Fault_Handler, (void *)Fault_Handler, (void *)Fault_Handler, (void *)Fault_Handler,
    (void *)Fault_Handler, 0, 0, 0, 0, (void *)Fault_Handler, (void *)Fault_Handler, 0,
    (void *)Fault_Handler, (void *)Fault_Handler,
};

/* ARM semihosting (bkpt 0xAB on M-profile). */
static int semihost(int op, const void *arg)
{
    register int r0 __asm("r0") = op;
    register const void *r1 __asm("r1") = arg;
    __asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

void sh_write0(const char *s) { semihost(0x04, s); }

int sh_open_wb(const char *name)
{
    size_t n = 0;
    while (name[n]) n++;
    const uintptr_t a[3] = {(uintptr_t)name, 5 /* "wb" */, n};
    return semihost(0x01, a);
}

int sh_write(int fd, const void *buf, size_t len)
{
    const uintptr_t a[3] = {(uintptr_t)fd, (uintptr_t)buf, len};
    return semihost(0x05, a);
}

void sh_close(int fd)
{
    const uintptr_t a[1] = {(uintptr_t)fd};
    semihost(0x02, a);
}

void sh_exit(int status)
{
    /* AArch32 SYS_EXIT: r1 holds the reason; ADP_Stopped_ApplicationExit (0x20026) = status 0,
       anything else (ADP_Stopped_RunTimeErrorUnknown, 0x20023) = status 1. */
    semihost(0x18, (const void *)(uintptr_t)(status == 0 ? 0x20026 : 0x20023));
    for (;;) {}
}

/* newlib stubs (nothing here allocates or does I/O through them). */
void *_sbrk(ptrdiff_t incr) { (void)incr; return (void *)-1; }
void _exit(int status) { sh_exit(status); for (;;) {} }
int _kill(int pid, int sig) { (void)pid; (void)sig; return -1; }
int _getpid(void) { return 1; }
