/* A panic inside the library aborts the host process (SIGABRT) instead of
 * hanging it. Needs the library built with the `panic-probe` feature, whose
 * granbed_panic_probe (not in the header) indexes a slice out of range.
 * The probe runs in a child process with a 10 s alarm: a panic handler that
 * spins would end by SIGALRM, and this program fails. POSIX only. */
#define _POSIX_C_SOURCE 200809L
#include <signal.h>
#include <stddef.h>
#include <stdio.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

double granbed_panic_probe(const double *p, size_t n, size_t i);

int main(void) {
    pid_t child = fork();
    if (child < 0) {
        perror("fork");
        return 1;
    }
    if (child == 0) {
        alarm(10);
        const double v[2] = {1.0, 2.0};
        volatile double x = granbed_panic_probe(v, 2, 5);
        (void)x;
        _exit(0); /* the out-of-range index did not panic */
    }
    int st = 0;
    if (waitpid(child, &st, 0) != child) {
        perror("waitpid");
        return 1;
    }
    if (WIFSIGNALED(st) && WTERMSIG(st) == SIGABRT) {
        printf("panic_abort: a panic aborts the process (SIGABRT)\n");
        return 0;
    }
    if (WIFSIGNALED(st))
        fprintf(stderr, "FAIL: the panicking call ended by signal %d, not SIGABRT%s\n", WTERMSIG(st),
                WTERMSIG(st) == SIGALRM ? " (it hung)" : "");
    else
        fprintf(stderr, "FAIL: the panicking call exited with status %d\n", WEXITSTATUS(st));
    return 1;
}
