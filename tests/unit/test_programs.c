/* tests/unit/test_programs.c: motion programs and the richer laws of time
 * (docs/motion-programs.md), against independent truths:
 *   - each standard law (normalised, programs.c prog_shape_eval) against its
 *     textbook closed form written out here (cycloidal, harmonic, 3-4-5,
 *     4-5-6-7) or Norton's published piecewise forms (modified trapezoid
 *     and sine, 8 digits), and its derivatives against central differences;
 *   - the ends (f(0) = 0, f(1) = 1, the zero rates each law promises) and
 *     the peak coefficients of velocity and acceleration;
 *   - a rise-dwell-return-dwell program driving a slider through mech_solve,
 *     row by row against the closed form with the chain rule by hand;
 *   - the load-time checks: a jump named at its boundary, a gap in the
 *     period, a user's f(u) that does not end at 1;
 *   - laws of t with exp, log, tanh, sqrt, division by an expression of t
 *     against their derivatives by hand, and a law not defined at some time
 *     an error naming that time. */
#include <math.h>

#include "helpers.h"
#include "load.h"

#define PI 3.14159265358979323846

typedef void (*closed_form)(double u, double f[3]);

static void cycloidal(double u, double f[3])
{
    f[0] = u - sin(2 * PI * u) / (2 * PI);
    f[1] = 1 - cos(2 * PI * u);
    f[2] = 2 * PI * sin(2 * PI * u);
}
static void harmonic(double u, double f[3])
{
    f[0] = (1 - cos(PI * u)) / 2;
    f[1] = PI / 2 * sin(PI * u);
    f[2] = PI * PI / 2 * cos(PI * u);
}
static void poly345(double u, double f[3])
{
    f[0] = 10 * pow(u, 3) - 15 * pow(u, 4) + 6 * pow(u, 5);
    f[1] = 30 * pow(u, 2) - 60 * pow(u, 3) + 30 * pow(u, 4);
    f[2] = 60 * u - 180 * pow(u, 2) + 120 * pow(u, 3);
}
static void poly4567(double u, double f[3])
{
    f[0] = 35 * pow(u, 4) - 84 * pow(u, 5) + 70 * pow(u, 6) - 20 * pow(u, 7);
    f[1] = 140 * pow(u, 3) - 420 * pow(u, 4) + 420 * pow(u, 5) - 140 * pow(u, 6);
    f[2] = 420 * pow(u, 2) - 1680 * pow(u, 3) + 2100 * pow(u, 4) - 840 * pow(u, 5);
}
/* Norton, Cam Design and Manufacturing Handbook (2nd ed.), eq. 3.x:
 * the modified trapezoid in five pieces, his 8-digit coefficients */
static void modtrap(double x, double f[3])
{
    const double a = 4.88812368, c = 0.38898448, k = 0.0309544;
    if (x <= 0.125) {
        f[0] = c * x - k * sin(4 * PI * x), f[1] = c - c * cos(4 * PI * x);
        f[2] = a * sin(4 * PI * x);
    } else if (x <= 0.375) {
        f[0] = 2.44406184 * x * x - 0.22203097 * x + 0.00723407;
        f[1] = a * x - 0.22203097, f[2] = a;
    } else if (x <= 0.625) {
        f[0] = 1.6110154 * x - k * sin(4 * PI * x - PI) - 0.3055077;
        f[1] = 1.6110154 - c * cos(4 * PI * x - PI), f[2] = a * sin(4 * PI * x - PI);
    } else if (x <= 0.875) {
        f[0] = 4.6660917 * x - 2.44406184 * x * x - 1.2292648;
        f[1] = 4.6660917 - a * x, f[2] = -a;
    } else {
        f[0] = 0.6110154 + c * x + k * sin(4 * PI * x - 3 * PI);
        f[1] = c + c * cos(4 * PI * x - 3 * PI), f[2] = -a * sin(4 * PI * x - 3 * PI);
    }
}
/* the modified sine in three pieces, Norton's coefficients */
static void modsine(double x, double f[3])
{
    const double c = 0.43990085, a = 5.5279571;
    if (x <= 0.125) {
        f[0] = c * x - 0.0350062 * sin(4 * PI * x), f[1] = c * (1 - cos(4 * PI * x));
        f[2] = a * sin(4 * PI * x);
    } else if (x <= 0.875) {
        double w = 4 * PI / 3 * x - PI / 6;
        f[0] = 0.28004957 + c * x - 0.31505577 * cos(w);
        f[1] = c * (1 + 3 * sin(w)), f[2] = a * cos(w);
    } else {
        double w = 2 * PI * (2 * x - 1);
        f[0] = 0.56009915 + c * x - 0.0350062 * sin(w);
        f[1] = c * (1 - cos(w)), f[2] = a * sin(w);
    }
}

/* trap: u, f, f', f'' (mpmath, 40 digits: f'' piecewise, integrated, scaled to f(1) = 1) */
static const double truth_trap[][4] = {
    {0.003, 2.7639724481800372457e-7, 0.00027638415070267052061, 0.18423427753367947545},
    {0.053, 0.0014907031646071865394, 0.083130493705747171571, 3.0201742568294690407},
    {0.103, 0.010286412059298752946, 0.28281044939453118574, 4.7025103219638556683},
    {0.153, 0.030476372211314402927, 0.52585199500711394344, 4.888123762813258315},
    {0.203, 0.062879126665186672993, 0.77025818314777685919, 4.888123762813258315},
    {0.253, 0.10750219052609208885, 1.0146643712884397749, 4.888123762813258315},
    {0.303, 0.16434556379403065049, 1.2590705594291026907, 4.888123762813258315},
    {0.353, 0.23340924646900235792, 1.5034767475697656064, 4.888123762813258315},
    {0.403, 0.31467355103977870326, 1.7450762357193267188, 4.5886472765552606022},
    {0.453, 0.40704451933678734699, 1.9341044255281827448, 2.7220769338871944992},
    {0.503, 0.505999723602755182, 1.9997236158492973295, -0.18423427753367947545},
    {0.553, 0.60450929683539281346, 1.9168695062942528284, -3.0201742568294690407},
    {0.603, 0.69571358794070124705, 1.7171895506054688143, -4.7025103219638556683},
    {0.653, 0.77552362778868559707, 1.4741480049928860566, -4.888123762813258315},
    {0.703, 0.84312087333481332701, 1.2297418168522231408, -4.888123762813258315},
    {0.753, 0.89849780947390791115, 0.98533562871156022505, -4.888123762813258315},
    {0.803, 0.94165443620596934951, 0.7409294405708973093, -4.888123762813258315},
    {0.853, 0.97259075353099764208, 0.49652325243023439355, -4.888123762813258315},
    {0.903, 0.99132644896022129674, 0.25492376428067328116, -4.5886472765552606022},
    {0.953, 0.99895548066321265301, 0.065895574471817255235, -2.7220769338871944992},
    {1.0, 1.0, 2.0067540006620698941e-47, -8.0831270196323558684e-42},
};
/* sine: u, f, f', f'' (mpmath, 40 digits: f'' piecewise, integrated, scaled to f(1) = 1) */
static const double truth_sine[][4] = {
    {0.003, 3.1257639493383687466e-7, 0.00031256158685798794287, 0.20834971178036299695},
    {0.053, 0.0016858294713327951733, 0.094011899607473598266, 3.415501416786350136},
    {0.103, 0.011632856906430763748, 0.31982905900371244676, 5.3180476692033721741},
    {0.153, 0.034463108664758891157, 0.59432902218953473599, 5.4899792495867489301},
    {0.203, 0.070960659200552315881, 0.86345094337618629547, 5.2355187715960206085},
    {0.253, 0.12049923166106308795, 1.1140616929099852934, 4.7522410004801489097},
    {0.303, 0.18187504161082267594, 1.3352083784725061133, 4.0612674938609348766},
    {0.353, 0.25336696053471488998, 1.5172258287251332644, 3.1927971096363894252},
    {0.403, 0.33281173741297738423, 1.6521590076751965902, 2.1847861709803925409},
    {0.453, 0.41769854317119535459, 1.7341106879213488178, 1.0812895928853486166},
    {0.503, 0.50527870595914810187, 1.7594991877890411234, -0.069464529021918093032},
    {0.553, 0.5926858413002545755, 1.7272149080065164371, -1.2171827176831346028},
    {0.603, 0.67706112684763871493, 1.6386688265174332706, -2.3117041808909043327},
    {0.653, 0.75567824663883955853, 1.4977308319741044783, -3.3051930786063563892},
    {0.703, 0.82606254418568623538, 1.3105605910336051464, -4.154229178710671992},
    {0.753, 0.88609917683755034179, 1.0853383413674984541, -4.8217055295020670027},
    {0.803, 0.93412554455331935864, 0.83190737602245294789, -5.2784502115440694794},
    {0.853, 0.96900395350123341523, 0.56134384428074263023, -5.5045012905272937579},
    {0.903, 0.99019112033090691991, 0.28829213284772127104, -5.1892804657768634755},
    {0.953, 0.99881875780293449445, 0.07452100734237548339, -3.0783845015794784405},
    {1.0, 1.0, -6.8082870883068888945e-47, -9.1411718132452090818e-42},
};

static const struct {
    prog_shape shape;
    closed_form truth;
    double tol;          /* of the truth: exact forms 1e-13, Norton's 8 digits 2e-6 */
    double vpeak, apeak; /* peak f', |f''| (textbook values) */
    int zero_ends;       /* f'' = 0 at both ends */
} laws[] = {
    {SHAPE_CYCLOIDAL, cycloidal, 1e-13, 2.0, 2 * PI, 1},
    {SHAPE_HARMONIC, harmonic, 1e-13, PI / 2, PI * PI / 2, 0},
    {SHAPE_345, poly345, 1e-12, 1.875, 5.7735, 1},
    {SHAPE_4567, poly4567, 1e-12, 2.1875, 7.5132, 1},
    {SHAPE_MODTRAP, modtrap, 2e-6, 2.0, 4.8881, 1},
    {SHAPE_MODSINE, modsine, 2e-6, 1.76, 5.5280, 1},
};

static prog_segment segment_of(prog_shape s)
{
    prog_segment sg = {.kind = PROG_RISE, .shape = s, .span = 1, .lift = 1};
    prog_shape_init(&sg);
    return sg;
}

Test(programs, laws_against_closed_forms)
{
    for (size_t k = 0; k < sizeof laws / sizeof laws[0]; k++) {
        prog_segment sg = segment_of(laws[k].shape);
        double worst[3] = {0, 0, 0};
        for (int i = 0; i <= 4000; i++) {
            double u = i / 4000.0, f[4], g[3];
            prog_shape_eval(&sg, u, f);
            laws[k].truth(u, g);
            for (int j = 0; j < 3; j++) {
                double e = fabs(f[j] - g[j]);
                worst[j] = fmax(worst[j], e);
                cr_assert(e <= laws[k].tol * fmax(1.0, fabs(g[j])), "%s: f%d(%g) = %.17g, truth "
                          "%.17g", prog_shape_name(laws[k].shape), j, u, f[j], g[j]);
            }
        }
        cr_log_info("[programs] %s: worst |f - truth| %.2g, |f' - truth| %.2g, |f'' - truth| "
                    "%.2g", prog_shape_name(laws[k].shape), worst[0], worst[1], worst[2]);
    }
}

/* f', f'', f''' against central differences of f, f', f'' (away from the
 * pieces' joints, where f''' jumps) */
Test(programs, derivatives_against_differences)
{
    const double h = 1e-5;
    for (size_t k = 0; k < sizeof laws / sizeof laws[0]; k++) {
        prog_segment sg = segment_of(laws[k].shape);
        for (int i = 1; i < 1000; i++) {
            double u = i / 1000.0 + 1.234e-4, f[4], fp[4], fm[4];
            if (fabs(u * 8 - nearbyint(u * 8)) < 1e-3)
                continue;
            prog_shape_eval(&sg, u, f);
            prog_shape_eval(&sg, u + h, fp);
            prog_shape_eval(&sg, u - h, fm);
            for (int j = 1; j <= 3; j++) {
                double fd = (fp[j - 1] - fm[j - 1]) / (2 * h);
                cr_assert(fabs(f[j] - fd) <= 1e-6 * fmax(1.0, fabs(f[j])), "%s: f(%d)(%g) = %.12g, "
                          "differences %.12g", prog_shape_name(laws[k].shape), j, u, f[j], fd);
            }
        }
    }
}

Test(programs, ends_and_peaks)
{
    for (size_t k = 0; k < sizeof laws / sizeof laws[0]; k++) {
        prog_segment sg = segment_of(laws[k].shape);
        const char *n = prog_shape_name(laws[k].shape);
        double f0[4], f1[4], vmax = 0, amax = 0;
        prog_shape_eval(&sg, 0, f0);
        prog_shape_eval(&sg, 1, f1);
        cr_assert(fabs(f0[0]) < 1e-15 && fabs(f1[0] - 1) < 1e-14, "%s: f(0) %g, f(1) %.17g", n,
                  f0[0], f1[0]);
        cr_assert(fabs(f0[1]) < 1e-13 && fabs(f1[1]) < 1e-13, "%s: f'(0) %g f'(1) %g", n, f0[1],
                  f1[1]);
        if (laws[k].zero_ends)
            cr_assert(fabs(f0[2]) < 1e-12 && fabs(f1[2]) < 1e-12, "%s: f''(0) %g f''(1) %g", n,
                      f0[2], f1[2]);
        else
            cr_assert(fabs(f0[2] - PI * PI / 2) < 1e-13 && fabs(f1[2] + PI * PI / 2) < 1e-13);
        for (int i = 0; i <= 100000; i++) {
            double f[4];
            prog_shape_eval(&sg, i / 100000.0, f);
            vmax = fmax(vmax, f[1]), amax = fmax(amax, fabs(f[2]));
        }
        cr_assert(fabs(vmax - laws[k].vpeak) < 5e-3 && fabs(amax - laws[k].apeak) < 5e-4,
                  "%s: peaks %.6g %.6g, textbook %.6g %.6g", n, vmax, amax, laws[k].vpeak,
                  laws[k].apeak);
    }
    /* the 4-5-6-7 has a zero jerk at its ends too */
    prog_segment sg = segment_of(SHAPE_4567);
    double f[4];
    prog_shape_eval(&sg, 0, f);
    cr_assert(fabs(f[3]) < 1e-12);
    prog_shape_eval(&sg, 1, f);
    cr_assert(fabs(f[3]) < 1e-12);
}

static const char *const SLIDER =
    "name: program\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, 0]}\n"
    "links:\n"
    "  block: {points: {B: [0, 0], C: [10, 0]}}\n"
    "joints:\n"
    "  - {slider: B, link: block, on: ground, through: O, angle: 0, name: x_B}\n"
    "sweep: {time: {from: 0 s, to: 2.5 s, steps: 900}}\n"
    "drivers:\n"
    "  - slider: x_B\n"
    "    displacement:\n"
    "      program:\n"
    "%s";

static mech_model *program_model(const char *body)
{
    char text[4096];
    snprintf(text, sizeof text, SLIDER, body);
    return load_text(text);
}

/* rise 20 mm cycloidal over 120 deg, dwell 60, return 3-4-5 over 120,
 * dwell 60, of the cam angle 144 deg/s * t + 30 deg, from 10 mm: s, v, a by
 * hand with the chain rule (x' = 144 deg/s, x'' = 0) */
static void closed_program(double t, double w, double x0, double out[3])
{
    const double D = PI / 180, x = fmod(x0 + w * t, 2 * PI), b = 120 * D;
    double f[3] = {0, 0, 0}, s0 = 0.010, h = 0.020;
    if (x < b)
        cycloidal(x / b, f), f[0] *= h, f[1] *= h, f[2] *= h;
    else if (x < 180 * D)
        f[0] = h, f[1] = f[2] = 0;
    else if (x < 300 * D) {
        poly345((x - 180 * D) / b, f);
        f[0] = h - h * f[0], f[1] *= -h, f[2] *= -h;
    }
    out[0] = s0 + f[0];
    out[1] = f[1] / b * w;
    out[2] = f[2] / (b * b) * w * w;
}

Test(programs, rise_dwell_return_dwell_solved)
{
    mech_model *m = program_model(
        "        of: 144 deg/s * t + 30 deg\n"
        "        start: 10 mm\n"
        "        period: 360 deg\n"
        "        segments:\n"
        "          - {rise: 20 mm, over: 120 deg, law: cycloidal}\n"
        "          - {dwell: 60 deg}\n"
        "          - {return: 20 mm, over: 120 deg, law: 3-4-5}\n"
        "          - {dwell: 60 deg}\n");
    mech_table t = must_solve(m, NULL);
    cr_assert_eq(t.nrows, 901);
    double worst[3] = {0, 0, 0};
    static const char *const col[3] = {"x_B.s", "x_B.v", "x_B.a"};
    for (int r = 0; r < t.nrows; r++) {
        double tm = mech_table_get(&t, r, 0), truth[3];
        closed_program(tm, 144 * PI / 180, 30 * PI / 180, truth);
        for (int k = 0; k < 3; k++) {
            double e = fabs(table_at(&t, r, col[k]) - truth[k]);
            worst[k] = fmax(worst[k], e);
            cr_assert(e <= 1e-12 * (k == 0 ? 0.03 : k == 1 ? 0.05 : 0.2), "row %d (t %g) %s: %.17g, "
                      "truth %.17g", r, tm, col[k], table_at(&t, r, col[k]), truth[k]);
        }
    }
    cr_log_info("[programs] solved program: worst s %.2g m, v %.2g m/s, a %.2g m/s^2", worst[0],
                worst[1], worst[2]);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* the message of the first error of loading body, and its line */
static const char *load_error(const char *body, int *line)
{
    static char msg[1024];
    char text[4096];
    snprintf(text, sizeof text, SLIDER, body);
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    int rc = mech_load_string(text, strlen(text), "p.yaml", &m, &d);
    cr_assert_neq(rc, MECH_OK, "loaded: %s", body);
    cr_assert_geq(d.count, 1);
    snprintf(msg, sizeof msg, "%s", d.entries[0].message);
    *line = d.entries[0].mark.line;
    mech_diag_free(&d);
    return msg;
}

Test(programs, acceleration_jump_named)
{
    int line;
    const char *e = load_error("        of: 360 deg/s * t\n"
                               "        segments:\n"
                               "          - {rise: 20 mm, over: 120 deg, law: harmonic}\n"
                               "          - {dwell: 60 deg}\n"
                               "          - {return: 20 mm, over: 120 deg, law: cycloidal}\n"
                               "          - {dwell: 60 deg}\n",
                               &line);
    /* f''(1) = -pi^2/2 of h/beta^2: 20 mm / (120 deg)^2 */
    char want[160];
    snprintf(want, sizeof want, "an acceleration jump of %.6g mm/deg^2 (d2s/dx2) at 120 deg "
             "between segment 1 (rise, harmonic) and segment 2 (dwell)",
             PI * PI / 2 * 20.0 / (120.0 * 120.0));
    cr_assert(strstr(e, want), "message '%s' lacks '%s'", e, want);
    cr_assert_eq(line, 16, "at line %d", line);
    /* velocity continuity only: loads */
    mech_model *m = program_model("        of: 360 deg/s * t\n"
                                  "        continuity: velocity\n"
                                  "        segments:\n"
                                  "          - {rise: 20 mm, over: 120 deg, law: harmonic}\n"
                                  "          - {dwell: 60 deg}\n"
                                  "          - {return: 20 mm, over: 120 deg, law: harmonic}\n"
                                  "          - {dwell: 60 deg}\n");
    mech_model_free(&m);
    /* a 4-5-6-7 rise against a harmonic return: -5 mm * pi^2 / 2 / (1 s)^2 */
    e = load_error("        segments:\n"
                   "          - {rise: 20 mm, over: 1 s, law: 3-4-5}\n"
                   "          - {return: 20 mm, over: 1 s, law: 3-4-5}\n"
                   "          - {rise: 5 mm, over: 1 s, law: 4-5-6-7}\n"
                   "          - {return: 5 mm, over: 1 s, law: harmonic}\n",
                   &line);
    cr_assert(strstr(e, "an acceleration jump of -24.674 mm/s^2 (d2s/dx2) at 3 s between "
                        "segment 3 (rise, 4-5-6-7) and segment 4 (return, harmonic)"), "%s", e);
    /* a user's u^2 ends at the rate 2 h / span: a velocity jump */
    e = load_error("        continuity: velocity\n"
                   "        segments:\n"
                   "          - {rise: 20 mm, over: 1 s, law: \"u^2\"}\n"
                   "          - {dwell: 1 s}\n",
                   &line);
    cr_assert(strstr(e, "a velocity jump of -40 mm/s (ds/dx) at 1 s between segment 1 (rise, "
                        "user law) and segment 2 (dwell)"), "%s", e);
}

Test(programs, period_and_laws_checked)
{
    int line;
    const char *e = load_error("        of: 360 deg/s * t\n"
                               "        period: 360 deg\n"
                               "        segments:\n"
                               "          - {rise: 20 mm, over: 120 deg, law: cycloidal}\n"
                               "          - {return: 20 mm, over: 180 deg, law: cycloidal}\n",
                               &line);
    cr_assert(strstr(e, "the segments cover 300 deg, not the period 360 deg: a gap of 60 deg "
                        "after segment 2"), "%s", e);
    e = load_error("        segments:\n"
                   "          - {rise: 20 mm, over: 1 s, law: \"u^2\"}\n"
                   "          - {return: 20 mm, over: 1 s, law: \"2 * u\"}\n", &line);
    cr_assert(strstr(e, "f(1) = 2"), "%s", e);
    e = load_error("        segments:\n"
                   "          - {rise: 20 mm, over: 1 s, law: cycloidl}\n", &line);
    cr_assert(strstr(e, "no standard law (cycloidal"), "%s", e);
    e = load_error("        segments:\n"
                   "          - {rise: 20 mm, over: 1 mm, law: cycloidal}\n", &line);
    cr_assert(strstr(e, "expected a time"), "%s", e);
}

/* A user's f(u) is evaluated with its exact derivatives: the cycloidal
 * written out agrees with the built-in one */
Test(programs, user_law_is_the_builtin)
{
    mech_model *m = program_model(
        "        segments:\n"
        "          - {rise: 20 mm, over: 1 s, law: \"u - sin(2 * pi * u) / (2 * pi / 1 rad)\"}\n"
        "          - {return: 20 mm, over: 1 s, law: cycloidal}\n");
    const mech_program *p = m->drivers[0].law->progs[0];
    cr_assert_eq(p->seg[0].shape, SHAPE_USER);
    for (int i = 0; i <= 100; i++) {
        double u = i / 100.0, f[4], g[4];
        prog_segment sg = segment_of(SHAPE_CYCLOIDAL);
        prog_shape_eval(&p->seg[0], u, f);
        prog_shape_eval(&sg, u, g);
        for (int k = 0; k < 4; k++)
            cr_assert(fabs(f[k] - g[k]) < 1e-13 * fmax(1, fabs(g[k])), "f%d(%g) %.17g %.17g", k,
                      u, f[k], g[k]);
    }
    mech_model_free(&m);
}

/* Laws of t with the functions of the loads, their derivatives by hand */
Test(programs, law_functions_closed_forms)
{
    const char *law = "10 mm * exp(-t / 2 s) + 5 mm * log(1 + t / 1 s) + 3 mm * tanh(t / 0.5 s) "
                      "+ 4 mm / (1 + t^2 / 1 s^2) + 2 mm * sqrt(1 + t / 1 s) + 1 mm * atan2(t, 1 s) / 1 rad";
    char body[1024];
    snprintf(body, sizeof body, "        segments: [{dwell: 1 s}]\n");
    (void)body;
    char text[4096];
    snprintf(text, sizeof text,
             "name: l\nground: {O: [0, 0]}\nlinks:\n  block: {points: {B: [0, 0], C: [1, 0]}}\n"
             "joints:\n  - {slider: B, link: block, on: ground, through: O, angle: 0, name: x_B}\n"
             "sweep: {time: {from: 0 s, to: 1 s, steps: 10}}\n"
             "drivers:\n  - {slider: x_B, displacement: \"%s\"}\n", law);
    mech_model *m = load_text(text);
    const struct mech_law *l = m->drivers[0].law;
    cr_assert(law_is_opaque(l));
    for (double t = 0.0; t <= 3.0; t += 0.125) {
        double e = exp(-t / 2), th = tanh(2 * t), q = 1 + t * t, r = sqrt(1 + t);
        double v = 0.010 * e + 0.005 * log(1 + t) + 0.003 * th + 0.004 / q + 0.002 * r +
                   0.001 * atan(t);
        double v1 = -0.005 * e + 0.005 / (1 + t) + 0.006 * (1 - th * th) - 0.008 * t / (q * q) +
                    0.001 / r + 0.001 / q;
        double v2 = 0.0025 * e - 0.005 / ((1 + t) * (1 + t)) - 0.024 * th * (1 - th * th) +
                    0.004 * (6 * t * t - 2) / (q * q * q) - 0.0005 / (r * r * r) -
                    0.002 * t / (q * q);
        double d1, d2, f = law_eval(l, t, &d1, &d2);
        cr_assert(fabs(f - v) < 1e-16 && fabs(d1 - v1) < 1e-16 && fabs(d2 - v2) < 1e-16,
                  "t %g: %.17g %.17g %.17g, by hand %.17g %.17g %.17g", t, f, d1, d2, v, v1, v2);
        double h = 1e-4, fp = law_eval(l, t + h, NULL, NULL), fm = law_eval(l, t - h, NULL, NULL);
        cr_assert(fabs(d1 - (fp - fm) / (2 * h)) < 1e-9 && fabs(d2 - (fp - 2 * f + fm) / (h * h)) < 1e-6);
    }
    mech_table t = must_solve(m, NULL);
    for (int r = 0; r < t.nrows; r++) {
        double tm = mech_table_get(&t, r, 0), d1, d2, f = law_eval(l, tm, &d1, &d2);
        cr_assert(fabs(table_at(&t, r, "x_B.s") - f) < 1e-15 &&
                  fabs(table_at(&t, r, "x_B.v") - d1) < 1e-15 &&
                  fabs(table_at(&t, r, "x_B.a") - d2) < 1e-15, "row %d", r);
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

/* a log of a negative number at t > 1.5 s: an error naming the time */
Test(programs, undefined_law_names_the_time)
{
    const char *text =
        "name: l\nground: {O: [0, 0]}\nlinks:\n  block: {points: {B: [0, 0], C: [1, 0]}}\n"
        "joints:\n  - {slider: B, link: block, on: ground, through: O, angle: 0, name: x_B}\n"
        "sweep: {time: {from: 0 s, to: 2 s, steps: 8}}\n"
        "drivers:\n  - {slider: x_B, displacement: \"1 m * log(1.6 - t / 1 s)\"}\n";
    mech_model *m = load_text(text);
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = {0};
    int rc = mech_solve(m, &o, &t, NULL, &d);
    cr_assert_neq(rc, MECH_OK);
    int found = 0;
    for (size_t i = 0; i < d.count; i++)
        found |= strstr(d.entries[i].message, "driver 'x_B': its law is not defined at t = 1.75 s: "
                                              "log of -0.15") != NULL;
    if (!found)
        mech_diag_print(&d, stderr);
    cr_assert(found);
    mech_table_free(&t);
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* the modified trapezoid and sine against a 40-digit integration of their
 * accelerations (mpmath: the truths above), not Norton's rounded numbers */
Test(programs, piecewise_laws_against_high_precision)
{
    const struct { prog_shape s; const double (*t)[4]; } cases[] = {
        {SHAPE_MODTRAP, truth_trap}, {SHAPE_MODSINE, truth_sine}};
    for (int k = 0; k < 2; k++) {
        prog_segment sg = segment_of(cases[k].s);
        double worst = 0;
        for (int i = 0; i < 21; i++) {
            double f[4];
            prog_shape_eval(&sg, cases[k].t[i][0], f);
            for (int j = 0; j < 3; j++)
                worst = fmax(worst, fabs(f[j] - cases[k].t[i][j + 1]));
        }
        cr_assert(worst < 1e-14, "%s: worst %.3g", prog_shape_name(cases[k].s), worst);
        cr_log_info("[programs] %s against 40 digits: worst %.2g", prog_shape_name(cases[k].s),
                    worst);
    }
}

/* `speed:` (x = speed * t, the cam angle at 60 rpm): the same program, and
 * a jump reported in time too */
Test(programs, speed_gives_the_cam_angle)
{
    mech_model *m = program_model(
        "        speed: 60 rpm\n"
        "        start: 10 mm\n"
        "        segments:\n"
        "          - {rise: 20 mm, over: 120 deg, law: cycloidal}\n"
        "          - {dwell: 60 deg}\n"
        "          - {return: 20 mm, over: 120 deg, law: 3-4-5}\n"
        "          - {dwell: 60 deg}\n");
    mech_table t = must_solve(m, NULL);
    static const char *const col[3] = {"x_B.s", "x_B.v", "x_B.a"};
    for (int r = 0; r < t.nrows; r++) {
        double tm = mech_table_get(&t, r, 0), truth[3];
        closed_program(tm, 2 * PI, 0, truth);
        for (int k = 0; k < 3; k++)
            cr_assert(fabs(table_at(&t, r, col[k]) - truth[k]) <= 1e-12 * (k == 0 ? 0.03 : k == 1 ? 0.2 : 2),
                      "row %d (t %g) %s: %.17g, truth %.17g", r, tm, col[k], table_at(&t, r, col[k]),
                      truth[k]);
    }
    mech_table_free(&t);
    mech_model_free(&m);
    int line;
    const char *e = load_error("        speed: 60 rpm\n"
                               "        segments:\n"
                               "          - {rise: 20 mm, over: 120 deg, law: simple harmonic}\n"
                               "          - {dwell: 240 deg}\n", &line);
    char want[200];  /* pi^2/2 h / beta^2 * omega^2: 20 mm / (2 pi / 3)^2 * (2 pi)^2 */
    snprintf(want, sizeof want, "(d2s/dx2 = %.6g mm/s^2 in time) at 120 deg",
             PI * PI / 2 * 20.0 * 9.0);
    cr_assert(strstr(e, want), "'%s' lacks '%s'", e, want);
}

/* an accelerating cam, x = 90 deg/s^2 * t^2 + 20 deg/s * t: the chain rule
 * with x'' != 0, p' = s'(x) x', p'' = s''(x) x'^2 + s'(x) x'' (a 4-5-6-7 rise
 * over 180 deg, a modified-sine return over 180 deg) */
Test(programs, accelerating_variable_chain_rule)
{
    mech_model *m = program_model(
        "        of: 90 deg/s^2 * t^2 + 20 deg/s * t\n"
        "        segments:\n"
        "          - {rise: 15 mm, over: 180 deg, law: 4-5-6-7}\n"
        "          - {return: 15 mm, over: 180 deg, law: modified-sine}\n");
    mech_table t = must_solve(m, NULL);
    const double D = PI / 180, b = PI, h = 0.015;
    prog_segment rise = segment_of(SHAPE_4567), ret = segment_of(SHAPE_MODSINE);
    double worst = 0;
    for (int r = 0; r < t.nrows; r++) {
        double tm = mech_table_get(&t, r, 0);
        double x = 90 * D * tm * tm + 20 * D * tm, x1 = 180 * D * tm + 20 * D, x2 = 180 * D;
        double xl = fmod(x, 2 * PI), f[4], s, s1, s2;
        if (xl < b) {
            prog_shape_eval(&rise, xl / b, f);
            s = h * f[0], s1 = h * f[1] / b, s2 = h * f[2] / (b * b);
        } else {
            prog_shape_eval(&ret, (xl - b) / b, f);
            s = h - h * f[0], s1 = -h * f[1] / b, s2 = -h * f[2] / (b * b);
        }
        double truth[3] = {s, s1 * x1, s2 * x1 * x1 + s1 * x2};
        static const char *const col[3] = {"x_B.s", "x_B.v", "x_B.a"};
        for (int k = 0; k < 3; k++) {
            double e = fabs(table_at(&t, r, col[k]) - truth[k]);
            worst = fmax(worst, e / (k == 0 ? h : k == 1 ? h * 10 : h * 100));
            cr_assert(e <= 1e-12 * (k == 0 ? h : k == 1 ? h * 10 : h * 100),
                      "row %d (t %g) %s: %.17g, truth %.17g", r, tm, col[k],
                      table_at(&t, r, col[k]), truth[k]);
        }
    }
    cr_log_info("[programs] accelerating variable: worst relative %.2g", worst);
    mech_table_free(&t);
    mech_model_free(&m);
}
