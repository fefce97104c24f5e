/* src/cli/cmd_opts.c: the command line's one option parser and the --help it
 * prints, both from a command's cmd_spec (src/cli/cli.h). */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "base.h"

/* ---- finding an option ----------------------------------------------- */

/* Does `arg` (up to its '=' when eq) spell one of names ("-o|--output")? */
static int spells(const char *names, const char *arg, size_t len)
{
    for (const char *s = names; *s;) {
        size_t n = strcspn(s, "|");
        if (n == len && strncmp(s, arg, len) == 0)
            return 1;
        s += n + (s[n] == '|');
    }
    return 0;
}

/* The option argv[*i] names, its value (the next argument, or after '=')
 * in *value, *i moved past it. NULL when no option is spelled so; *value
 * is then NULL. *missing: a value was needed and there is none. */
static const cmd_opt *find(const cmd_spec *spec, int argc, char **argv, int *i,
                           const char **value, size_t *name_len, int *missing)
{
    const char *arg = argv[*i];
    const char *eq = strncmp(arg, "--", 2) == 0 ? strchr(arg, '=') : NULL;
    size_t len = eq ? (size_t)(eq - arg) : strlen(arg);
    *value = NULL;
    *missing = 0;
    *name_len = len;
    for (const cmd_opt *o = spec->opts; o->names || o->label; o++) {
        if (!o->names || !spells(o->names, arg, len))
            continue;
        if (o->kind == CMD_OPT_FLAG || o->kind == CMD_OPT_HELP)
            *value = eq ? eq + 1 : NULL;  /* a value here is refused */
        else if (eq)
            *value = eq + 1;
        else if (*i + 1 < argc)
            *value = argv[++*i];
        else
            *missing = 1;
        return o;
    }
    return NULL;
}

/* The spelling listed first (the manifest's name of the option). */
static const char *first_name(const cmd_opt *o, char *buf, size_t size)
{
    snprintf(buf, size, "%.*s", (int)strcspn(o->names, "|"), o->names);
    return buf;
}

/* ---- reading a value ------------------------------------------------- */

/* A whole number in decimal digits, an optional '-' first: 1, else 0. */
static int whole_number(const char *s, long long *v)
{
    const char *d = s + (*s == '-');
    if (*d < '0' || *d > '9' || d[strspn(d, "0123456789")] != '\0')
        return 0;
    errno = 0;
    char *end;
    *v = strtoll(s, &end, 10);
    return errno == 0;
}

/* A decimal number ("12", "-0.5", "1e-10", ".5"): 1, else 0. */
static int decimal_number(const char *s, double *v)
{
    const char *p = s + (*s == '-' || *s == '+');
    size_t digits = strspn(p, "0123456789");
    p += digits;
    if (*p == '.') {
        size_t frac = strspn(p + 1, "0123456789");
        digits += frac;
        p += 1 + frac;
    }
    if (digits == 0)
        return 0;
    if (*p == 'e' || *p == 'E') {
        p += 1 + (p[1] == '-' || p[1] == '+');
        size_t exp = strspn(p, "0123456789");
        if (exp == 0)
            return 0;
        p += exp;
    }
    if (*p != '\0')
        return 0;
    *v = strtod(s, NULL);
    return 1;
}

/* What a value strtod reads whole but the grammar refuses is told ("0x10":
 * digits only), so the refusal says why the number is not one. */
static const char *why_not(const cmd_opt *o, const char *text)
{
    char *end;
    (void)strtod(text, &end);
    if (end == text || *end != '\0')
        return "";
    return o->kind == CMD_OPT_REAL ? ": write it as a decimal number"
                                   : ": write it with digits only";
}

static int refuse(const cmd_spec *spec, const char *name, const cmd_opt *o, const char *text,
                  const char *why)
{
    char msg[600];
    snprintf(msg, sizeof msg, "%s %s, not '%s'%s", name, o->expect, text, why);
    return cmd_usage_error(spec->name, "%s", msg);
}

/* The word of o->words that `text` is, exactly; a refusal names the one
 * nearest ("position": did you mean 'positions'?). */
static int read_word(const cmd_spec *spec, const char *name, const cmd_opt *o, const char *text,
                     int *target)
{
    const char *words[32];
    size_t n = 0;
    for (const cmd_word *w = o->words; w->word; w++) {
        if (strcmp(w->word, text) == 0) {
            *target = w->value;
            return -1;
        }
        if (n < sizeof words / sizeof words[0])
            words[n++] = w->word;
    }
    const char *near = nearest_name(text, words, n);
    char why[96] = "";
    if (near)
        snprintf(why, sizeof why, " (did you mean '%s'?)", near);
    return refuse(spec, name, o, text, why);
}

/* The value of option o (spelled `name`) into its target in args. */
static int store(const cmd_spec *spec, const char *name, const cmd_opt *o, const char *value,
                 void *args)
{
    void *target = (char *)args + o->at;
    long long whole;
    double real;
    switch (o->kind) {
    case CMD_OPT_FLAG:
        *(int *)target = o->flag;
        return -1;
    case CMD_OPT_TEXT:
        *(const char **)target = value;
        return -1;
    case CMD_OPT_INT:
    case CMD_OPT_LONG:
        if (!whole_number(value, &whole))
            return refuse(spec, name, o, value, why_not(o, value));
        if (!(whole >= o->lo && whole <= o->hi))
            return refuse(spec, name, o, value, "");
        if (o->kind == CMD_OPT_INT)
            *(int *)target = (int)whole;
        else
            *(long *)target = (long)whole;
        return -1;
    case CMD_OPT_U64: {
        char *end;
        errno = 0;
        unsigned long long u = strtoull(value, &end, 10);
        if (value[0] < '0' || value[0] > '9' || *end || errno)
            return refuse(spec, name, o, value, value[0] == '-' ? "" : why_not(o, value));
        *(unsigned long long *)target = u;
        return -1;
    }
    case CMD_OPT_REAL:
        if (!decimal_number(value, &real))
            return refuse(spec, name, o, value, why_not(o, value));
        if (!(real >= o->lo && real <= o->hi) || ((o->flags & CMD_OPEN_LO) && real == o->lo) ||
            ((o->flags & CMD_OPEN_HI) && real == o->hi))
            return refuse(spec, name, o, value, "");
        *(double *)target = real;
        return -1;
    case CMD_OPT_WORD:
        return read_word(spec, name, o, value, target);
    case CMD_OPT_CALL:
        return o->call(spec->name, target, value);
    case CMD_OPT_HELP:
        break;
    }
    return -1;
}

/* ---- the command line ------------------------------------------------ */

/* "unknown option '--forcse' (did you mean '--forces'?)": the long names
 * compared without their dashes (a typo is a third of the word at most). */
static int unknown(const cmd_spec *spec, const char *arg)
{
    const char *names[128];
    char buf[128][40];
    size_t n = 0;
    for (const cmd_opt *o = spec->opts; o->names || o->label; o++)
        for (const char *s = o->names ? o->names : ""; *s && n < 128;) {
            size_t len = strcspn(s, "|");
            if (len > 2 && s[1] == '-' && len < sizeof buf[0]) {  /* long names only */
                snprintf(buf[n], sizeof buf[n], "%.*s", (int)len - 2, s + 2);
                names[n] = buf[n];
                n++;
            }
            s += len + (s[len] == '|');
        }
    char word[64];
    snprintf(word, sizeof word, "%.*s", (int)strcspn(arg + 2, "="), arg + 2);
    const char *near = strncmp(arg, "--", 2) == 0 ? nearest_name(word, names, n) : NULL;
    if (near && edit_distance(word, near) > 2)
        near = NULL;  /* "--forces" is not a typo of "--frames" */
    char msg[300];
    snprintf(msg, sizeof msg, "unknown option '%.200s'%s%s%s", arg,
             near ? " (did you mean '--" : "", near ? near : "", near ? "'?)" : "");
    return cmd_usage_error(spec->name, "%s", msg);
}

/* One file (a non-option argument) for the command. */
static int operand(const cmd_spec *spec, void *args, const char *arg, int argc)
{
    void *target = (char *)args + spec->file_at;
    if (spec->max_files == 1) {
        const char **file = target;
        if (*file)
            return cmd_usage_error(spec->name, "one file at a time ('%s' is a second file)", arg);
        *file = arg;
        return -1;
    }
    cmd_operands *ops = target;
    if (!ops->v && !(ops->v = calloc((size_t)argc, sizeof *ops->v)))
        return fprintf(stderr, "mech %s: out of memory\n", spec->name), MECH_EXIT_IO;
    ops->v[ops->n++] = arg;
    return -1;
}

static int is_option(const char *arg)
{
    return arg[0] == '-' && arg[1] != '\0';
}

int cmd_opts_parse(const cmd_spec *spec, int argc, char **argv, void *args)
{
    int nfiles = 0;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i], *value;
        size_t len;
        int missing, code;
        if (!is_option(arg)) {
            if ((code = operand(spec, args, arg, argc)) >= 0)
                return code;
            nfiles++;
            continue;
        }
        const cmd_opt *o = find(spec, argc, argv, &i, &value, &len, &missing);
        char name[64];
        snprintf(name, sizeof name, "%.*s", (int)(len < 60 ? len : 60), arg);
        if (!o)
            return unknown(spec, arg);
        if (missing)
            return cmd_usage_error(spec->name, "option '%s' needs a value", name);
        if ((o->kind == CMD_OPT_FLAG || o->kind == CMD_OPT_HELP) && value)
            return cmd_usage_error(spec->name, "option '%s' takes no value", arg);
        if (o->kind == CMD_OPT_HELP) {
            cmd_opts_help(spec, stdout);
            return MECH_EXIT_OK;
        }
        if ((code = store(spec, name, o, value, args)) >= 0)
            return code;
    }
    if (nfiles < spec->min_files)
        return cmd_usage_error(spec->name, "%s", spec->no_files);
    return -1;
}

void cmd_opts_each(const cmd_spec *spec, int argc, char **argv,
                   void (*fn)(void *ctx, const cmd_opt *opt, const char *name, const char *value),
                   void *ctx)
{
    for (int i = 1; i < argc; i++) {
        const char *value;
        size_t len;
        int missing;
        const cmd_opt *o = is_option(argv[i]) ? find(spec, argc, argv, &i, &value, &len, &missing)
                                              : NULL;
        char name[64];
        if (o)
            fn(ctx, o, first_name(o, name, sizeof name), value);
        else
            fn(ctx, NULL, argv[i], NULL);
    }
}

/* ---- the help ---------------------------------------------------------- */

/* "  LABEL    first line\n" and the other lines at the column. */
static void help_entry(const cmd_spec *spec, const cmd_opt *o, FILE *out)
{
    int width = 2 + (int)strlen(o->label);
    fprintf(out, "  %s", o->label);
    const char *line = o->help ? o->help : "";
    if (*line)
        fprintf(out, "%*s", width + 2 <= spec->column ? spec->column - width : 2, "");
    for (int first = 1; first || *line; first = 0) {
        size_t n = strcspn(line, "\n");
        if (!first)
            fprintf(out, "%*s", spec->column, "");
        fprintf(out, "%.*s\n", (int)n, line);
        line += n + (line[n] == '\n');
    }
}

void cmd_opts_help(const cmd_spec *spec, FILE *out)
{
    fprintf(out, "%s\n%s\noptions:\n", spec->usage, spec->about);
    for (const cmd_opt *o = spec->opts; o->names || o->label; o++)
        if (o->label)
            help_entry(spec, o, out);
    fprintf(out, "\n%s", spec->exits);
}
