/* C interface of the static library built from examples/embedded (liblugre_embedded.a). */
#ifndef LUGRE_FF_H
#define LUGRE_FF_H

#include <stdint.h>

#define LUGRE_FF_AXES 4

typedef struct {
    float fc;     /* Coulomb force [N] */
    float fs;     /* static (breakaway) force [N] */
    float sigma2; /* viscous coefficient [N s/m] */
    float vs;     /* Stribeck velocity [m/s] */
} LugreFfStatic;

typedef struct {
    float sigma0; /* bristle stiffness [N/m] */
    float sigma1; /* bristle damping [N s/m] */
    LugreFfStatic positive;
    LugreFfStatic negative;
} LugreFfParams;

/* 0 on success, -1 axis out of range or null pointer, -2 parameters out of range. */
int32_t lugre_ff_init(uint32_t axis, const LugreFfParams *params);
/* Friction force [N] at v [m/s], then the state advanced over dt [s]; once per period. */
float lugre_ff_step(uint32_t axis, float v, float dt);
void lugre_ff_reset(uint32_t axis);
float lugre_ff_state(uint32_t axis);

#endif
