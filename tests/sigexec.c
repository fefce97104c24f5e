/* tests/sigexec.c: run a command with known signal dispositions.
 *
 *   sigexec default COMMAND [ARG...]   every signal at its default action,
 *                                      none blocked
 *   sigexec hostile COMMAND [ARG...]   SIGTERM, SIGHUP and SIGPIPE ignored,
 *                                      SIGINT and SIGQUIT blocked
 *
 * Ignored signals and the signal mask survive exec, and a non-interactive
 * shell can neither trap nor reset a signal that was ignored when it
 * started (POSIX `trap`), so a suite run under nohup, or by a CI runner or
 * a parent that ignores SIGTERM, would hand that on to the mech it kills.
 * tests/lib.sh therefore runs every suite under `default`; `hostile` is
 * such a parent, for testing that (tests/signals.sh). Exit status 127 when
 * COMMAND cannot be run, 2 on bad usage. */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

static void set_default(void)
{
    for (int sig = 1; sig <= SIGRTMAX; sig++)
        if (sig != SIGKILL && sig != SIGSTOP)
            signal(sig, SIG_DFL);  /* fails harmlessly on the C library's own */
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, NULL);
}

static void set_hostile(void)
{
    signal(SIGTERM, SIG_IGN);
    signal(SIGHUP, SIG_IGN);
    signal(SIGPIPE, SIG_IGN);
    sigset_t block;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGQUIT);
    sigprocmask(SIG_BLOCK, &block, NULL);
}

int main(int argc, char **argv)
{
    if (argc < 3 || (strcmp(argv[1], "default") != 0 && strcmp(argv[1], "hostile") != 0)) {
        fprintf(stderr, "usage: sigexec default|hostile COMMAND [ARG...]\n");
        return 2;
    }
    if (strcmp(argv[1], "default") == 0)
        set_default();
    else
        set_hostile();
    execvp(argv[2], argv + 2);
    fprintf(stderr, "sigexec: cannot run %s: %s\n", argv[2], strerror(errno));
    return 127;
}
