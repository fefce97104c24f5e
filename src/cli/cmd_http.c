/* src/cli/cmd_http.c: the HTTP/1.1 server of `mech watch` (see cmd_http.h): the
 * request parser, then the connections driven by poll(). Every answer
 * closes its connection ("Connection: close"), so no request is ever read
 * after a first one, and a request's size, its time to arrive and the
 * number of connections are bounded. Nothing here opens a file. */
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <unistd.h>

#include "cli.h"
#include "base.h"

/* ------------------------------------------------------------------ */
/* Parsing a request.                                                  */

static int refuse(http_request *r, int status, const char *why)
{
    r->status = status;
    r->why = why;
    return status;
}

/* The length of the line at s (up to end), without its "\n" or "\r\n";
 * *next is where the following line starts. -1: a CR not before LF. */
static long line_at(const char *s, const char *end, const char **next)
{
    const char *nl = memchr(s, '\n', (size_t)(end - s));
    const char *stop = nl ? nl : end;
    long n = stop - s;
    if (n > 0 && s[n - 1] == '\r')
        n--;
    if (memchr(s, '\r', (size_t)n))
        return -1;
    *next = nl ? nl + 1 : end;
    return n;
}

/* The end of the headers (after the empty line), or 0 when not there yet. */
static size_t head_end(const char *buf, size_t len)
{
    for (size_t i = 0; i + 1 < len; i++)
        if (buf[i] == '\n' && (buf[i + 1] == '\n' ||
                               (buf[i + 1] == '\r' && i + 2 < len && buf[i + 2] == '\n')))
            return i + (buf[i + 1] == '\n' ? 2 : 3);
    return 0;
}

static int is_tchar(unsigned char c)  /* RFC 9110 token characters */
{
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
           (c && strchr("!#$%&'*+-.^_`|~", c));
}

/* Host: 127.0.0.1 or localhost, with our port or none. */
static int host_ok(const char *v, size_t n, int port)
{
    const char *colon = memchr(v, ':', n);
    size_t name = colon ? (size_t)(colon - v) : n;
    int ours = (name == 9 && memcmp(v, "127.0.0.1", 9) == 0) ||
               (name == 9 && strncasecmp(v, "localhost", 9) == 0);
    if (!ours || !colon)
        return ours;
    size_t digits = n - name - 1;
    if (digits < 1 || digits > 5)
        return 0;
    long p = 0;
    for (size_t i = 0; i < digits; i++) {
        if (colon[1 + i] < '0' || colon[1 + i] > '9')
            return 0;
        p = 10 * p + (colon[1 + i] - '0');
    }
    return p == port;
}

/* The request line: METHOD SP TARGET SP HTTP/1.x; the target's bounds. */
static int request_line(const char *s, long n, http_request *r, const char **target,
                        size_t *tlen)
{
    const char *sp1 = memchr(s, ' ', (size_t)n);
    const char *sp2 = sp1 ? memchr(sp1 + 1, ' ', (size_t)(s + n - sp1 - 1)) : NULL;
    if (!sp1 || !sp2 || sp1 == s || sp2 == sp1 + 1)
        return refuse(r, 400, "the request line is not METHOD TARGET HTTP/1.1");
    for (const char *c = s; c < sp1; c++)
        if (!is_tchar((unsigned char)*c))
            return refuse(r, 400, "the method is not a token");
    const char *ver = sp2 + 1;
    long vlen = s + n - ver;
    if (vlen == 8 && memcmp(ver, "HTTP/", 5) == 0 && ver[6] == '.' && ver[5] >= '0' &&
        ver[5] <= '9' && ver[7] >= '0' && ver[7] <= '9') {
        if (memcmp(ver, "HTTP/1.1", 8) != 0 && memcmp(ver, "HTTP/1.0", 8) != 0)
            return refuse(r, 505, "only HTTP/1.0 and HTTP/1.1 are spoken here");
    } else {
        return refuse(r, 400, "the request line does not end in an HTTP version");
    }
    *target = sp1 + 1;
    *tlen = (size_t)(sp2 - sp1 - 1);
    if (*tlen > HTTP_MAX_TARGET)
        return refuse(r, 414, "the request target is too long");
    for (size_t i = 0; i < *tlen; i++)
        if ((unsigned char)(*target)[i] <= 0x20 || (unsigned char)(*target)[i] >= 0x7f)
            return refuse(r, 400, "the request target has a character that is not allowed");
    if ((*target)[0] != '/')
        return refuse(r, 400, "the request target must be a path starting with /");
    if (sp1 - s != 3 || memcmp(s, "GET", 3) != 0)
        return refuse(r, 405, "only GET is answered here");
    return 0;
}

/* The headers from s to end: each "Name: value"; Host once and ours; no
 * body. */
static int headers(const char *s, const char *end, int port, http_request *r)
{
    int nhost = 0, count = 0, host_good = 0;
    const char *next;
    long n;
    while ((n = line_at(s, end, &next)) != 0) {
        if (n < 0)
            return refuse(r, 400, "a header line has a stray carriage return");
        if (++count > HTTP_MAX_HEADERS)
            return refuse(r, 431, "too many header lines");
        const char *colon = memchr(s, ':', (size_t)n);
        if (!colon || colon == s)
            return refuse(r, 400, "a header line is not Name: value");
        for (const char *c = s; c < colon; c++)
            if (!is_tchar((unsigned char)*c))
                return refuse(r, 400, "a header name is not a token (or a folded line)");
        const char *v = colon + 1, *ve = s + n;
        for (const char *c = v; c < ve; c++)
            if (((unsigned char)*c < 0x20 && *c != '\t') || *c == 0x7f)
                return refuse(r, 400, "a header value has a control character");
        while (v < ve && (*v == ' ' || *v == '\t'))
            v++;
        while (ve > v && (ve[-1] == ' ' || ve[-1] == '\t'))
            ve--;
        size_t name = (size_t)(colon - s), vn = (size_t)(ve - v);
        if (name == 4 && strncasecmp(s, "Host", 4) == 0) {
            nhost++;
            host_good = host_ok(v, vn, port);
        } else if (name == 17 && strncasecmp(s, "Transfer-Encoding", 17) == 0) {
            return refuse(r, 400, "a GET request has no body");
        } else if (name == 14 && strncasecmp(s, "Content-Length", 14) == 0 &&
                   !(vn == 1 && *v == '0')) {
            return refuse(r, 400, "a GET request has no body");
        }
        s = next;
    }
    if (nhost != 1)
        return refuse(r, 400, nhost ? "more than one Host header" : "no Host header");
    if (!host_good)
        return refuse(r, 403, "the Host must be 127.0.0.1 or localhost (with this server's "
                              "port): this server answers its own address only");
    return 0;
}

/* The route of the target: "/", "/state" or "/state?since=N". */
static int route(const char *t, size_t n, http_request *r)
{
    if (n == 1 && t[0] == '/') {
        r->route = HTTP_PAGE;
        return 0;
    }
    if (n < 6 || memcmp(t, "/state", 6) != 0 || (n > 6 && t[6] != '?'))
        return refuse(r, 404, "no such page: the pages are / and /state");
    r->route = HTTP_STATE;
    if (n == 6)
        return 0;
    if (n <= 13 || memcmp(t + 6, "?since=", 7) != 0 || n - 13 > 18)
        return refuse(r, 400, "/state takes ?since=N, N a whole number");
    long long v = 0;
    for (size_t i = 13; i < n; i++) {
        if (t[i] < '0' || t[i] > '9')
            return refuse(r, 400, "/state takes ?since=N, N a whole number");
        v = 10 * v + (t[i] - '0');
    }
    r->since = v;
    return 0;
}

int http_parse(const char *buf, size_t len, int port, http_request *r)
{
    *r = (http_request){0, NULL, HTTP_PAGE, -1};
    if (memchr(buf, '\0', len))
        return refuse(r, 400, "the request has a NUL byte");
    size_t head = head_end(buf, len);
    if (head == 0 || head > HTTP_MAX_REQUEST) {
        const char *nl = memchr(buf, '\n', len);
        if ((nl ? (size_t)(nl - buf) : len) > HTTP_MAX_TARGET + 32)
            return refuse(r, 414, "the request line is too long");
        if (len >= HTTP_MAX_REQUEST)
            return refuse(r, 431, "the request's headers are too long");
        return 0;
    }
    const char *next, *target = NULL, *end = buf + head;
    size_t tlen = 0;
    long n = line_at(buf, end, &next);
    if (n <= 0)
        return refuse(r, 400, n < 0 ? "the request line has a stray carriage return"
                                    : "the request starts with an empty line");
    if (request_line(buf, n, r, &target, &tlen) || headers(next, end, port, r) ||
        route(target, tlen, r))
        return r->status;
    r->status = 200;
    return 200;
}

/* ------------------------------------------------------------------ */
/* The connections.                                                    */

enum { PHASE_READ, PHASE_WAIT, PHASE_WRITE, PHASE_DRAIN };

static int nonblocking(int fd)
{
    int fl = fcntl(fd, F_GETFL);
    return fl < 0 || fcntl(fd, F_SETFL, fl | O_NONBLOCK) < 0 ||
           fcntl(fd, F_SETFD, FD_CLOEXEC) < 0 ? -1 : 0;
}

int http_open(http_server *s, int port, char *err, size_t errsize)
{
    memset(s, 0, sizeof *s);
    for (int i = 0; i < HTTP_MAX_CONNS; i++)
        s->conn[i].fd = -1;
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons((unsigned short)port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);  /* 127.0.0.1, never another interface */
    socklen_t alen = sizeof a;
    int one = 1;
    s->fd = socket(AF_INET, SOCK_STREAM, 0);
    if (s->fd < 0 || setsockopt(s->fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) < 0 ||
        bind(s->fd, (struct sockaddr *)&a, sizeof a) < 0 || listen(s->fd, 16) < 0 ||
        getsockname(s->fd, (struct sockaddr *)&a, &alen) < 0 || nonblocking(s->fd) < 0) {
        snprintf(err, errsize, "cannot listen on 127.0.0.1:%d: %s", port, strerror(errno));
        if (s->fd >= 0)
            close(s->fd);
        s->fd = -1;
        return -1;
    }
    s->port = ntohs(a.sin_port);
    return 0;
}

static void conn_close(http_conn *c)
{
    if (c->fd >= 0)
        close(c->fd);
    free(c->out);
    c->out = NULL;
    c->fd = -1;
}

void http_close(http_server *s)
{
    for (int i = 0; i < HTTP_MAX_CONNS; i++)
        conn_close(&s->conn[i]);
    if (s->fd >= 0)
        close(s->fd);
    s->fd = -1;
}

static const char *reason(int status)
{
    switch (status) {
    case 200: return "OK";
    case 400: return "Bad Request";
    case 403: return "Forbidden";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 408: return "Request Timeout";
    case 414: return "URI Too Long";
    case 431: return "Request Header Fields Too Large";
    case 503: return "Service Unavailable";
    default: return "HTTP Version Not Supported";
    }
}

/* The page may run its own inline script and style and fetch /state;
 * nothing else, from anywhere. */
#define PAGE_POLICY "default-src 'none'; style-src 'unsafe-inline'; script-src 'unsafe-inline'; " \
                    "connect-src 'self'; img-src data:; base-uri 'none'; form-action 'none'; " \
                    "frame-ancestors 'none'"

/* The whole answer into c->out; the connection then writes it. */
static void answer(http_conn *c, int status, const char *type, const char *body, size_t len)
{
    char head[1024];
    int n = snprintf(head, sizeof head,
                     "HTTP/1.1 %d %s\r\nContent-Type: %s\r\nContent-Length: %zu\r\n"
                     "Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n"
                     "Referrer-Policy: no-referrer\r\nX-Frame-Options: DENY\r\n%s%s"
                     "Connection: close\r\n\r\n",
                     status, reason(status), type, len,
                     status == 405 ? "Allow: GET\r\n" : "",
                     strncmp(type, "text/html", 9) == 0
                         ? "Content-Security-Policy: " PAGE_POLICY "\r\n" : "");
    free(c->out);
    c->out = malloc((size_t)n + len);
    c->phase = PHASE_WRITE;
    c->sent = 0;
    c->deadline = clock_seconds() + HTTP_WRITE_MS / 1e3;
    if (!c->out) {  /* out of memory: the client sees the connection closed */
        c->nout = 0;
        return;
    }
    memcpy(c->out, head, (size_t)n);
    if (len)
        memcpy(c->out + n, body, len);
    c->nout = (size_t)n + len;
}

static void answer_error(http_conn *c, int status, const char *why)
{
    char body[300];
    int n = snprintf(body, sizeof body, "%d %s: %s\n", status, reason(status), why);
    answer(c, status, "text/plain; charset=utf-8", body, (size_t)n);
}

static void answer_state(http_conn *c, const http_site *site)
{
    answer(c, 200, "application/json", site->state, site->state_len);
}

/* A complete request (or a refused one): its answer, or a long poll. */
static void handle(http_server *s, http_conn *c, const http_site *site)
{
    http_request r;
    if (http_parse(c->in, c->nin, s->port, &r) == 0)
        return;  /* more to come */
    if (r.status != 200)
        answer_error(c, r.status, r.why);
    else if (r.route == HTTP_PAGE)
        answer(c, 200, "text/html; charset=utf-8", site->page, site->page_len);
    else if (r.since >= 0 && r.since >= site->version) {
        c->phase = PHASE_WAIT;
        c->since = r.since;
        c->deadline = clock_seconds() + HTTP_HOLD_MS / 1e3;
    } else {
        answer_state(c, site);
    }
}

static void on_readable(http_server *s, http_conn *c, const http_site *site)
{
    char scratch[512];
    int reading = c->phase == PHASE_READ;
    char *into = reading ? c->in + c->nin : scratch;
    size_t room = reading ? HTTP_MAX_REQUEST - c->nin : sizeof scratch;
    ssize_t got = room ? recv(c->fd, into, room, 0) : 0;
    if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR))
        return;
    if (got <= 0) {  /* closed by the client (or an error): nothing to answer */
        conn_close(c);
        return;
    }
    if (!reading)
        return;  /* waiting or draining: what comes is not read */
    c->nin += (size_t)got;
    c->in[c->nin] = '\0';
    handle(s, c, site);
}

static void on_writable(http_conn *c)
{
    ssize_t put = c->nout > c->sent
                      ? send(c->fd, c->out + c->sent, c->nout - c->sent, MSG_NOSIGNAL) : 0;
    if (put < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR))
        return;
    if (put < 0 || c->out == NULL) {
        conn_close(c);
        return;
    }
    c->sent += (size_t)put;
    if (c->sent < c->nout)
        return;
    /* all sent: no more writes; whatever the client still sends is read
       and dropped until it closes (closing with unread data would reset
       the connection and could lose the answer) */
    shutdown(c->fd, SHUT_WR);
    free(c->out);
    c->out = NULL;
    c->phase = PHASE_DRAIN;
    c->deadline = clock_seconds() + 1.0;
}

/* Accept what is waiting; a connection with no free slot gets a 503. */
static void accept_all(http_server *s)
{
    for (;;) {
        int fd = accept(s->fd, NULL, NULL);
        if (fd < 0)
            return;  /* EAGAIN: none left (or an error: the next poll tries again) */
        http_conn *c = NULL;
        for (int i = 0; i < HTTP_MAX_CONNS && !c; i++)
            if (s->conn[i].fd < 0)
                c = &s->conn[i];
        if (!c || nonblocking(fd) < 0) {
            static const char busy[] = "HTTP/1.1 503 Service Unavailable\r\nContent-Length: 0"
                                       "\r\nConnection: close\r\n\r\n";
            (void)send(fd, busy, sizeof busy - 1, MSG_NOSIGNAL | MSG_DONTWAIT);
            close(fd);
            continue;
        }
        memset(c, 0, sizeof *c);
        c->fd = fd;
        c->phase = PHASE_READ;
        c->deadline = clock_seconds() + HTTP_READ_MS / 1e3;
    }
}

/* Long polls a newer version ends; connections past their time. */
static void on_time(http_conn *c, const http_site *site, double t)
{
    if (c->phase == PHASE_WAIT && (site->version > c->since || t >= c->deadline))
        answer_state(c, site);
    else if (t >= c->deadline && c->phase == PHASE_READ)
        answer_error(c, 408, "the request did not arrive in time");
    else if (t >= c->deadline)
        conn_close(c);
}

void http_serve(http_server *s, const http_site *site, int timeout_ms)
{
    struct pollfd fds[HTTP_MAX_CONNS + 1];
    int who[HTTP_MAX_CONNS + 1], n = 0;
    double t = clock_seconds();
    for (int i = 0; i < HTTP_MAX_CONNS; i++) {
        http_conn *c = &s->conn[i];
        if (c->fd < 0)
            continue;
        on_time(c, site, t);
        if (c->fd < 0)
            continue;
        double left = (c->deadline - t) * 1e3 + 1;  /* wake up for the deadline */
        if (left < timeout_ms)
            timeout_ms = left > 0 ? (int)left : 0;
        fds[n] = (struct pollfd){c->fd, c->phase == PHASE_WRITE ? POLLOUT : POLLIN, 0};
        who[n++] = i;
    }
    fds[n] = (struct pollfd){s->fd, POLLIN, 0};
    who[n++] = -1;
    if (poll(fds, (nfds_t)n, timeout_ms) <= 0)
        return;  /* time up, or a signal */
    for (int k = 0; k < n; k++) {
        if (!fds[k].revents)
            continue;
        if (who[k] < 0) {
            accept_all(s);
            continue;
        }
        http_conn *c = &s->conn[who[k]];
        if (c->phase == PHASE_WRITE && (fds[k].revents & (POLLOUT | POLLERR | POLLHUP)))
            on_writable(c);
        else if (fds[k].revents & (POLLIN | POLLERR | POLLHUP))
            on_readable(s, c, site);
    }
}
