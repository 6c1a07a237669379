/* The registry of solid models compiled in (the "none"-style choice of the
 * house style: a scene picks one by name, --model or solid.model). */
#include "solid_model.h"

#include <stdio.h>
#include <string.h>

#include "solid_mps.h"
#include "solid_tlsph.h"

static const struct solid_model_ops *const models[] = {&solid_mps_ops, &solid_tlsph_ops, NULL};

const struct solid_model_ops *solid_model_find(const char *name)
{
    for (int k = 0; name && models[k]; k++)
        if (strcmp(models[k]->name, name) == 0)
            return models[k];
    return NULL;
}

const char *solid_model_names(void)
{
    static char names[256];
    if (!names[0])
        for (int k = 0; models[k]; k++)
            snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", k ? ", " : "",
                     models[k]->name);
    return names;
}
