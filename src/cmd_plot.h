/* src/cmd_plot.h: the `mech plot` and `mech animate` commands (src/cmd_plot.c;
 * the drawing itself is src/plot.c and src/plot_anim.c, docs/plots.md). */
#ifndef MECH_CMD_PLOT_H
#define MECH_CMD_PLOT_H

extern const char cmd_plot_help[];
extern const char cmd_animate_help[];
/* argv[0] is the command name; returns a MECH_EXIT_* status. */
int cmd_plot(int argc, char **argv);
int cmd_animate(int argc, char **argv);

#endif
