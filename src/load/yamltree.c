/* src/load/yamltree.c: turn libyaml's event stream into a small document tree
 * with a mark on every node, under fixed limits (input is untrusted).
 * The only file that includes <yaml.h>. */
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

#include "base.h"

const yaml_limits yaml_default_limits = {
    .max_bytes = 32u << 20,   /* 32 MiB: a chain of 100 000 loops is ~16 MiB; a larger
                                 file is refused from its size, before the seconds and
                                 the gigabyte its tree would take */
    .max_depth = 32,
    .max_nodes = 8u << 20,
    .max_scalar = 4096,
};

typedef struct builder {
    const char *file;
    const yaml_limits *lim;
    mech_diag *d;
    size_t nodes;
    ynode *stack[64];  /* open collections; depth bounded by lim->max_depth <= 64 */
    int depth;
    ynode *root;
} builder;

static mech_mark mark_of(yaml_mark_t m)
{
    return (mech_mark){(int)m.line + 1, (int)m.column + 1};  /* libyaml is 0-based */
}

const char *ynode_kind_name(ynode_kind k)
{
    switch (k) {
    case YNODE_SCALAR: return "a single value";
    case YNODE_SEQ: return "a list";
    case YNODE_MAP: return "a mapping";
    }
    return "?";
}

void ytree_free(ynode *n)
{
    if (!n)
        return;
    for (size_t i = 0; i < n->nraw; i++)
        ytree_free(n->items[i]);
    free(n->items);
    free(n->text);
    free(n);
}

ynode *ymap_get(const ynode *map, const char *key)
{
    if (!map || map->kind != YNODE_MAP)
        return NULL;
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i];
        if (k->kind == YNODE_SCALAR && strcmp(k->text, key) == 0)
            return map->items[2 * i + 1];
    }
    return NULL;
}

/* Items arrive one by one (for a mapping: key, value, key, ...); `nraw`
 * counts them until the collection closes, when `n` is set. */
static int append(ynode *parent, ynode *child)
{
    size_t count = parent->nraw;
    /* grow by doubling: capacity is the next power of two >= count + 1 */
    if ((count & (count - 1)) == 0) {
        ynode **items = xrealloc_array(parent->items, count ? 2 * count : 2, sizeof *items);
        if (!items)
            return -1;
        parent->items = items;
    }
    parent->items[parent->nraw++] = child;
    parent->n = parent->kind == YNODE_MAP ? parent->nraw / 2 : parent->nraw;
    return 0;
}

/* Attach a finished node to the open collection (or make it the root).
 * When there is no memory to, n is freed and the error recorded here, at
 * n's mark: a caller must not touch n after a failure (on_open used to
 * read n->mark for its message after n was freed). */
static int attach(builder *b, ynode *n)
{
    if (b->depth == 0) {
        b->root = n;
        return 0;
    }
    if (append(b->stack[b->depth - 1], n) < 0) {
        mech_mark at = n->mark;
        ytree_free(n);
        return diag_nomem(b->d, b->file, at);
    }
    return 0;
}

static ynode *new_node(builder *b, ynode_kind kind, yaml_mark_t m)
{
    if (++b->nodes > b->lim->max_nodes) {
        diag_error(b->d, b->file, mark_of(m), "file too large: more than %zu YAML nodes",
                   b->lim->max_nodes);
        return NULL;
    }
    ynode *n = xcalloc(1, sizeof *n);
    if (!n) {
        diag_nomem(b->d, b->file, mark_of(m));
        return NULL;
    }
    n->kind = kind;
    n->mark = mark_of(m);
    return n;
}

static int on_scalar(builder *b, const yaml_event_t *ev)
{
    if (ev->data.scalar.length > b->lim->max_scalar) {
        diag_error(b->d, b->file, mark_of(ev->start_mark),
                   "value too long (%zu bytes; at most %zu)", (size_t)ev->data.scalar.length,
                   b->lim->max_scalar);
        return -1;
    }
    ynode *n = new_node(b, YNODE_SCALAR, ev->start_mark);
    if (!n)
        return -1;
    n->len = ev->data.scalar.length;
    n->text = malloc(n->len + 1);
    if (!n->text) {
        mech_mark at = n->mark;
        free(n);
        return diag_nomem(b->d, b->file, at);
    }
    memcpy(n->text, ev->data.scalar.value, n->len);
    n->text[n->len] = '\0';
    if (strlen(n->text) != n->len) {
        mech_mark at = n->mark;
        ytree_free(n);
        return diag_error(b->d, b->file, at, "value contains a NUL character");
    }
    n->quoted = ev->data.scalar.style != YAML_PLAIN_SCALAR_STYLE;
    return attach(b, n);
}

static int on_open(builder *b, const yaml_event_t *ev, ynode_kind kind)
{
    if (b->depth >= b->lim->max_depth || b->depth >= 64)
        return diag_error(b->d, b->file, mark_of(ev->start_mark),
                          "nesting too deep (more than %d levels)", b->lim->max_depth);
    ynode *n = new_node(b, kind, ev->start_mark);
    if (!n)
        return -1;
    if (attach(b, n) < 0)
        return -1;  /* n is freed, the error recorded */
    b->stack[b->depth++] = n;
    return 0;
}

/* Small mappings (a point's x and y, a joint's few keys: most of a large
 * file's) compare their keys pairwise, with no allocation. */
enum { FEW_KEYS = 16 };

static void mark_duplicate_few(ynode *map)
{
    for (size_t i = 1; i < map->n; i++) {
        ynode *k = map->items[2 * i];
        for (size_t j = 0; j < i && k->kind == YNODE_SCALAR; j++) {
            const ynode *e = map->items[2 * j];
            if (e->kind == YNODE_SCALAR && strcmp(e->text, k->text) == 0) {
                k->dup_of = map->items[2 * j];
                break;
            }
        }
    }
}

/* Mark each repeated scalar key of a closed mapping with its first use. A
 * hash of the keys keeps a mapping of 10^5 links linear. */
static int mark_duplicate_keys(ynode *map)
{
    if (map->kind != YNODE_MAP || map->n < 2)
        return 0;
    if (map->n <= FEW_KEYS) {
        mark_duplicate_few(map);
        return 0;
    }
    name_map seen = {0};
    int rc = 0;
    for (size_t i = 0; i < map->n && rc == 0; i++) {
        ynode *k = map->items[2 * i];
        if (k->kind != YNODE_SCALAR)
            continue;
        int first = name_map_get(&seen, k->text);
        if (first >= 0)
            k->dup_of = map->items[2 * (size_t)first];
        else
            rc = name_map_put(&seen, k->text, (int)i);
    }
    name_map_free(&seen);
    return rc;
}

static int on_close(builder *b, const yaml_event_t *ev)
{
    ynode *n = b->stack[--b->depth];
    if (mark_duplicate_keys(n) < 0)
        return diag_nomem(b->d, b->file, mark_of(ev->start_mark));
    return 0;
}

/* What libyaml's context ("while parsing a block mapping") is about, in words
 * for the note that points at its start. */
static const char *context_noun(const char *context)
{
    static const struct { const char *key, *noun; } table[] = {
        {"mapping", "the mapping"},     {"block collection", "the list"},
        {"sequence", "the list"},       {"quoted scalar", "the quoted value"},
        {"simple key", "the key"},      {"plain scalar", "the value"},
        {"block scalar", "the text block"},
    };
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
        if (strstr(context, table[i].key))
            return table[i].noun;
    return NULL;
}

/* libyaml's messages are about tokens and events; say what went wrong in
 * the file's terms, and point a note at the construct that was open. */
static int parser_error(builder *b, const yaml_parser_t *p, const char *text, size_t len)
{
    mech_mark at = mark_of(p->problem_mark), ctx = mark_of(p->context_mark);
    const char *problem = p->problem ? p->problem : "malformed YAML";
    const char *context = p->context ? p->context : "";
    size_t pos = p->problem_mark.index;
    char c = pos < len ? text[pos] : '\0';
    char msg[256];
    const char *note = NULL;
    char note_buf[128];
    if (strstr(problem, "tab character") ||
        (strstr(problem, "cannot start any token") && c == '\t')) {
        snprintf(msg, sizeof msg, "tab character; YAML indentation must use spaces");
    } else if (strstr(problem, "cannot start any token")) {
        snprintf(msg, sizeof msg, "a value cannot start with '%c'; put the value in quotes", c);
    } else if (strstr(problem, "mapping values are not allowed")) {
        snprintf(msg, sizeof msg, "unexpected ':' (is this line indented too far, or does a "
                                  "value that contains ': ' need quotes?)");
    } else if (strstr(problem, "did not find expected key")) {
        snprintf(msg, sizeof msg, "this line does not line up with the keys of the mapping it "
                                  "is in (check the indentation)");
        snprintf(note_buf, sizeof note_buf, "the mapping starts here; its keys are at column %d",
                 ctx.col);
        note = note_buf;
    } else if (strstr(problem, "did not find expected '-'")) {
        snprintf(msg, sizeof msg, "expected a '- ' item of the list here (check the "
                                  "indentation)");
        snprintf(note_buf, sizeof note_buf, "the list starts here; its items are at column %d",
                 ctx.col);
        note = note_buf;
    } else if (strstr(problem, "expected ',' or ']'") || strstr(problem, "expected ',' or '}'")) {
        int seq = strstr(problem, "']'") != NULL;
        snprintf(msg, sizeof msg, "expected ',' or '%c': the %s opened with '%c' is not closed",
                 seq ? ']' : '}', seq ? "list" : "mapping", seq ? '[' : '{');
        snprintf(note_buf, sizeof note_buf, "the %s starts here", seq ? "list" : "mapping");
        note = note_buf;
    } else if (strstr(problem, "end of stream") && strstr(context, "quoted")) {
        snprintf(msg, sizeof msg, "the file ends inside a quoted value (a closing quote is "
                                  "missing)");
        note = "the quoted value starts here";
    } else {
        snprintf(msg, sizeof msg, "%s", problem);
        const char *noun = context_noun(context);
        if (noun) {
            snprintf(note_buf, sizeof note_buf, "%s starts here", noun);
            note = note_buf;
        }
    }
    diag_error(b->d, b->file, at, "YAML syntax: %s", msg);
    if (note && p->context && (ctx.line != at.line || ctx.col != at.col))
        diag_note(b->d, b->file, ctx, "%s", note);
    return MECH_EINPUT;
}

static int handle(builder *b, const yaml_event_t *ev, int *ndocs)
{
    switch (ev->type) {
    case YAML_DOCUMENT_START_EVENT:
        if (++*ndocs > 1)
            return diag_error(b->d, b->file, mark_of(ev->start_mark),
                              "more than one YAML document ('---'); a file holds one mechanism");
        return 0;
    case YAML_ALIAS_EVENT:
        return diag_error(b->d, b->file, mark_of(ev->start_mark),
                          "YAML alias '*%s' is not supported; write the value out in full",
                          (const char *)ev->data.alias.anchor);
    case YAML_SCALAR_EVENT:
        return on_scalar(b, ev);
    case YAML_SEQUENCE_START_EVENT:
        return on_open(b, ev, YNODE_SEQ);
    case YAML_MAPPING_START_EVENT:
        return on_open(b, ev, YNODE_MAP);
    case YAML_SEQUENCE_END_EVENT:
    case YAML_MAPPING_END_EVENT:
        return on_close(b, ev);
    default:
        return 0;
    }
}

ynode *ytree_parse(const char *text, size_t len, const char *file, const yaml_limits *lim,
                   mech_diag *d)
{
    builder b = {file, lim ? lim : &yaml_default_limits, d, 0, {0}, 0, NULL};
    if (len > b.lim->max_bytes) {
        diag_error(d, file, (mech_mark){0, 0}, "file too large (%zu bytes; at most %zu)", len,
                   b.lim->max_bytes);
        return NULL;
    }
    yaml_parser_t parser;
    if (!yaml_parser_initialize(&parser)) {
        diag_nomem(d, file, (mech_mark){0, 0});
        return NULL;
    }
    yaml_parser_set_input_string(&parser, (const unsigned char *)text, len);
    int ndocs = 0, rc = 0, done = 0;
    while (!done && rc == 0) {
        yaml_event_t ev;
        if (!yaml_parser_parse(&parser, &ev)) {
            rc = parser_error(&b, &parser, text, len);
            break;
        }
        done = ev.type == YAML_STREAM_END_EVENT;
        rc = handle(&b, &ev, &ndocs);
        yaml_event_delete(&ev);
    }
    yaml_parser_delete(&parser);
    if (rc != 0) {
        ytree_free(b.root);
        return NULL;
    }
    if (!b.root)
        diag_error(d, file, (mech_mark){1, 1}, "the file holds no mechanism (it is empty or only "
                                               "comments): expected 'name', 'ground', 'links' "
                                               "and 'driver'");
    return b.root;
}

/* ---- trees built by the loader (the drawn form, load_drawn.c) -------- */

ynode *ynode_new(ynode_kind kind, const char *text, mech_mark mark)
{
    ynode *n = xcalloc(1, sizeof *n);
    if (!n)
        return NULL;
    n->kind = kind;
    n->mark = mark;
    if (kind == YNODE_SCALAR) {
        n->text = xstrdup(text ? text : "");
        if (!n->text) {
            free(n);
            return NULL;
        }
        n->len = strlen(n->text);
    }
    return n;
}

int ynode_push(ynode *parent, ynode *child)
{
    if (!child || append(parent, child) < 0) {
        ytree_free(child);
        return -1;
    }
    return 0;
}

ynode *ytree_copy(const ynode *n)
{
    ynode *c = ynode_new(n->kind, n->text, n->mark);
    if (!c)
        return NULL;
    c->quoted = n->quoted;
    c->dup_of = n->dup_of;  /* the original's key: only its mark is read */
    for (size_t i = 0; i < n->nraw; i++)
        if (ynode_push(c, ytree_copy(n->items[i])) < 0) {
            ytree_free(c);
            return NULL;
        }
    return c;
}
