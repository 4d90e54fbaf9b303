/* navsim tradeoff: speed against error of every modelling choice of a scene (tradeoff_cmd.c). */
#ifndef NAVSIM_TRADEOFF_CMD_H
#define NAVSIM_TRADEOFF_CMD_H

int navsim_tradeoff(int argc, char **argv);

#endif /* NAVSIM_TRADEOFF_CMD_H */
