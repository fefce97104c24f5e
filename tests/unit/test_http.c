/* tests/unit/test_http.c: the request parser of mech watch's server
 * (http_parse, src/cli/cmd_http.c): what it answers, what it refuses and with
 * which status: malformed request lines and headers, requests too long,
 * another Host (DNS rebinding), other methods, other paths (traversal
 * attempts included: the server maps no path to a file, so each is a 404),
 * and requests that have not fully arrived yet. */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

#define PORT 41234

static http_request req;

/* The status of request text s (NUL-terminated) to a server on PORT. */
static int parse(const char *s)
{
    return http_parse(s, strlen(s), PORT, &req);
}

/* "GET TARGET HTTP/1.1" with Host 127.0.0.1:PORT and a user agent. */
static int get(const char *target)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "GET %s HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUser-Agent: t\r\n\r\n",
             target, PORT);
    return parse(buf);
}

Test(http, the_two_routes)
{
    cr_assert_eq(get("/"), 200);
    cr_assert_eq(req.route, HTTP_PAGE);
    cr_assert_eq(req.since, -1);
    cr_assert_eq(get("/state"), 200);
    cr_assert_eq(req.route, HTTP_STATE);
    cr_assert_eq(req.since, -1);
    cr_assert_eq(get("/state?since=0"), 200);
    cr_assert_eq(req.since, 0);
    cr_assert_eq(get("/state?since=123456789012"), 200);
    cr_assert_eq(req.since, 123456789012LL);
    cr_assert_null(req.why);
}

Test(http, bad_since)
{
    cr_assert_eq(get("/state?since=-1"), 400);
    cr_assert_eq(get("/state?since="), 400);
    cr_assert_eq(get("/state?since=1x"), 400);
    cr_assert_eq(get("/state?since=1234567890123456789"), 400);  /* 19 digits: overflow */
    cr_assert_eq(get("/state?x=1"), 400);
    cr_assert_not_null(req.why);
}

Test(http, other_paths_and_traversal)
{
    static const char *const paths[] = {
        "/index.html", "/state/", "/stateX", "//", "/../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd",
        "/state/../../etc/passwd", "/./", "/?x=1", "/etc/passwd", "/..", "/%00",
    };
    for (size_t i = 0; i < sizeof paths / sizeof paths[0]; i++)
        cr_assert_eq(get(paths[i]), 404, "%s: %d", paths[i], req.status);
    cr_assert(strstr(req.why, "no such page"));
}

Test(http, target_forms)
{
    cr_assert_eq(get("http://127.0.0.1/"), 400);  /* absolute form: not ours */
    cr_assert_eq(get("*"), 400);
    cr_assert_eq(get("state"), 400);
    cr_assert_eq(parse("GET /\x01 HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), 400);
    cr_assert_eq(parse("GET /\xc3\xa9 HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), 400);
}

Test(http, methods)
{
    cr_assert_eq(parse("POST / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), 405);
    cr_assert_eq(parse("HEAD / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), 405);
    cr_assert_eq(parse("get / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), 405);
    cr_assert_eq(parse("G(T / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), 400);
}

Test(http, versions)
{
    cr_assert_eq(parse("GET / HTTP/1.0\r\nHost: localhost\r\n\r\n"), 200);
    cr_assert_eq(parse("GET / HTTP/2.0\r\nHost: localhost\r\n\r\n"), 505);
    cr_assert_eq(parse("GET / HTTP/1.1x\r\nHost: localhost\r\n\r\n"), 400);
    cr_assert_eq(parse("GET / http/1.1\r\nHost: localhost\r\n\r\n"), 400);
    cr_assert_eq(parse("GET /\r\nHost: localhost\r\n\r\n"), 400);  /* HTTP/0.9 */
}

Test(http, malformed_lines)
{
    cr_assert_eq(parse("GET  / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), 400);  /* two spaces */
    cr_assert_eq(parse("GET / HTTP/1.1 \r\nHost: 127.0.0.1\r\n\r\n"), 400);
    cr_assert_eq(parse("\r\nGET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), 400);
    cr_assert_eq(parse("GET / HTTP/1.1\r\nHost 127.0.0.1\r\n\r\n"), 400);  /* no colon */
    cr_assert_eq(parse("GET / HTTP/1.1\r\n: x\r\nHost: 127.0.0.1\r\n\r\n"), 400);
    cr_assert_eq(parse("GET / HTTP/1.1\r\nHost : 127.0.0.1\r\n\r\n"), 400);  /* space in name */
    cr_assert_eq(parse("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n x: folded\r\n\r\n"), 400);
    cr_assert_eq(parse("GET / HTTP/1.1\r\nHost: 127.0.0.1\rX: y\r\n\r\n"), 400);  /* bare CR */
    cr_assert_eq(parse("GET / HTTP/1.1\r\nX: a\x01z\r\nHost: 127.0.0.1\r\n\r\n"), 400);
    char nul[] = "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX: a\0b\r\n\r\n";
    cr_assert_eq(http_parse(nul, sizeof nul - 1, PORT, &req), 400);
    cr_assert(strstr(req.why, "NUL"));
}

Test(http, line_endings)
{
    cr_assert_eq(parse("GET / HTTP/1.1\nHost: 127.0.0.1\n\n"), 200);  /* bare LF */
    cr_assert_eq(parse("GET /state HTTP/1.1\r\nHost:127.0.0.1\r\nAccept: */*\r\n\r\n"), 200);
    cr_assert_eq(parse("GET / HTTP/1.1\r\nHost: \t127.0.0.1 \t\r\n\r\n"), 200);  /* OWS */
}

Test(http, host_checked)
{
    char buf[256];
    static const char *const good[] = {"127.0.0.1", "localhost", "LocalHost", "127.0.0.1:41234",
                                       "localhost:41234"};
    static const char *const bad[] = {
        "evil.example", "evil.example:41234", "127.0.0.1:80", "localhost:4123",
        "127.0.0.1:412345", "127.0.0.1:", "127.0.0.10", "127.0.0.1.evil.example",
        "localhost.evil.example", "[::1]:41234", "0.0.0.0", "192.168.1.2:41234",
        "localhost:41234x", "",
    };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        snprintf(buf, sizeof buf, "GET / HTTP/1.1\r\nHost: %s\r\n\r\n", good[i]);
        cr_assert_eq(parse(buf), 200, "Host %s: %d", good[i], req.status);
    }
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(buf, sizeof buf, "GET / HTTP/1.1\r\nHost: %s\r\n\r\n", bad[i]);
        cr_assert_eq(parse(buf), 403, "Host '%s': %d", bad[i], req.status);
    }
    cr_assert(strstr(req.why, "127.0.0.1 or localhost"));
}

Test(http, host_missing_or_twice)
{
    cr_assert_eq(parse("GET / HTTP/1.1\r\n\r\n"), 400);
    cr_assert(strstr(req.why, "no Host"));
    cr_assert_eq(parse("GET / HTTP/1.0\r\n\r\n"), 400);
    cr_assert_eq(parse("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nhost: evil.example\r\n\r\n"), 400);
    cr_assert(strstr(req.why, "more than one Host"));
    cr_assert_eq(parse("GET / HTTP/1.1\r\nHost: evil.example\r\nHost: 127.0.0.1\r\n\r\n"), 400);
}

Test(http, no_body)
{
    cr_assert_eq(parse("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 0\r\n\r\n"), 200);
    cr_assert_eq(parse("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 5\r\n\r\nhello"),
                 400);
    cr_assert_eq(parse("GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: chunked\r\n\r\n"),
                 400);
}

Test(http, incomplete_requests_wait)
{
    static const char full[] = "GET /state?since=3 HTTP/1.1\r\nHost: localhost\r\n\r\n";
    for (size_t n = 0; n < sizeof full - 1; n++)
        cr_assert_eq(http_parse(full, n, PORT, &req), 0, "the first %zu bytes", n);
    cr_assert_eq(http_parse(full, sizeof full - 1, PORT, &req), 200);
    cr_assert_eq(req.since, 3);
}

Test(http, oversized)
{
    char *buf = malloc(3 * HTTP_MAX_REQUEST);
    cr_assert_not_null(buf);
    /* a target one byte too long, and one just short enough (both complete) */
    int n = sprintf(buf, "GET /");
    memset(buf + n, 'a', HTTP_MAX_TARGET);
    sprintf(buf + n + HTTP_MAX_TARGET, " HTTP/1.1\r\nHost: localhost\r\n\r\n");
    cr_assert_eq(parse(buf), 414);
    sprintf(buf + n + HTTP_MAX_TARGET - 1, " HTTP/1.1\r\nHost: localhost\r\n\r\n");
    cr_assert_eq(parse(buf), 404);  /* within the limit: simply no such page */
    /* a request line that never ends: refused before the buffer is full */
    memset(buf + n, 'a', 2 * HTTP_MAX_TARGET);
    cr_assert_eq(http_parse(buf, (size_t)n + 2 * HTTP_MAX_TARGET, PORT, &req), 414);
    /* headers that never end: refused once the buffer is full */
    n = sprintf(buf, "GET / HTTP/1.1\r\nHost: localhost\r\n");
    while (n < HTTP_MAX_REQUEST)
        n += sprintf(buf + n, "X-Filler: 0123456789\r\n");
    cr_assert_eq(http_parse(buf, HTTP_MAX_REQUEST, PORT, &req), 431);
    cr_assert_eq(http_parse(buf, HTTP_MAX_REQUEST - 30, PORT, &req), 0);  /* not yet */
    /* too many header lines, the whole request still short */
    n = sprintf(buf, "GET / HTTP/1.1\r\nHost: localhost\r\n");
    for (int i = 0; i < HTTP_MAX_HEADERS; i++)
        n += sprintf(buf + n, "X: %d\r\n", i);
    sprintf(buf + n, "\r\n");
    cr_assert_eq(parse(buf), 431);
    free(buf);
}
