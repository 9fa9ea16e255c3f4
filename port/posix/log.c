/* SPDX-License-Identifier: MIT */
/*
 * log.c: one line per message on stderr.
 *
 * On a terminal or in a file a line reads "program: level: message". When
 * stderr is connected to the systemd journal (JOURNAL_STREAM names the same
 * device and inode as stderr, as sd-daemon(3) recommends) the line starts
 * with the syslog priority instead ("<4>message"): journald strips it, keeps
 * the level, and adds the program name itself.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "port.h"

/* Process-wide by nature: there is one stderr. */
static struct {
    char program[64];
    urrt_log_level max_level;
    bool journal;
    urrt_log_sink_fn sink;
    void *sink_ctx;
} log_cfg = {"urrt", URRT_LOG_INFO, false, NULL, NULL};

static bool stderr_is_journal(void)
{
    const char *env = getenv("JOURNAL_STREAM");
    unsigned long long dev, ino;
    struct stat st;
    if (env == NULL || sscanf(env, "%llu:%llu", &dev, &ino) != 2 || fstat(STDERR_FILENO, &st) != 0) {
        return false;
    }
    return (unsigned long long)st.st_dev == dev && (unsigned long long)st.st_ino == ino;
}

void urrt_log_init(const char *program, urrt_log_level max_level)
{
    const char *base = program != NULL ? strrchr(program, '/') : NULL;
    snprintf(log_cfg.program, sizeof log_cfg.program, "%s",
             base != NULL ? base + 1 : program != NULL ? program : "urrt");
    log_cfg.max_level = max_level;
    log_cfg.journal = stderr_is_journal();
}

void urrt_log_set_level(urrt_log_level max_level)
{
    log_cfg.max_level = max_level;
}

void urrt_log_set_sink(urrt_log_sink_fn sink, void *ctx)
{
    log_cfg.sink = sink;
    log_cfg.sink_ctx = ctx;
}

const char *urrt_log_level_name(urrt_log_level level)
{
    switch (level) {
    case URRT_LOG_ERR: return "error";
    case URRT_LOG_WARNING: return "warning";
    case URRT_LOG_NOTICE: return "notice";
    case URRT_LOG_INFO: return "info";
    case URRT_LOG_DEBUG: return "debug";
    default: return "log";
    }
}

void urrt_log(urrt_log_level level, const char *fmt, ...)
{
    char message[1024];
    char line[1200];
    va_list ap;
    int n;
    int saved_errno = errno;

    if (level > log_cfg.max_level) {
        return;
    }
    va_start(ap, fmt);
    n = vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    if (n >= (int)sizeof message) {
        memcpy(message + sizeof message - 4, "...", 4);
    }
    if (log_cfg.sink != NULL) {
        log_cfg.sink(log_cfg.sink_ctx, level, message);
        errno = saved_errno;
        return;
    }
    if (log_cfg.journal) {
        n = snprintf(line, sizeof line, "<%d>%s\n", (int)level, message);
    } else {
        n = snprintf(line, sizeof line, "%s: %s: %s\n", log_cfg.program, urrt_log_level_name(level), message);
    }
    if (n > (int)sizeof line - 1) {
        n = (int)sizeof line - 1;
        line[n - 1] = '\n';
    }
    /* One write per line, so that lines from several processes sharing
     * stderr do not interleave. A failed write has nowhere to be reported. */
    if (write(STDERR_FILENO, line, (size_t)n) < 0) {
        (void)0;
    }
    errno = saved_errno;
}
