// SPDX-License-Identifier: MIT
// Cost predictions shared by the scenes (see exp_cost.h).
#include "exp_cost.h"

#include <math.h>

#include "dem_scaling.h"
#include "dem_vec.h"

double exp_lightest_dt_crit(const dem_gsd *real_gsd, double real_density, double real_k_n, double lambda)
{
    dem_gsd gsd = dem_scale_gsd(real_gsd, lambda);
    double d_min = dem_gsd_min_diameter(&gsd);
    double m_min = dem_scale_density(real_density, lambda) * DEM_PI / 6 * d_min * d_min * d_min;
    return sqrt(m_min / dem_scale_stiffness(real_k_n, lambda)); // eq. 14
}

double exp_predicted_peak_memory_mb(double granules)
{
    const double base_mb = 9.5, mb_per_granule = 2.1e-3;
    return base_mb + mb_per_granule * granules;
}
