// bodypoint study orders: the measured order of every step-based method (paper table "Methods").
#pragma once

#include <ostream>

namespace bodypoint::cli {

/// Writes `method,nominal,measured,points,h_first,h_last,err_first,err_last` rows.
void write_orders(std::ostream& csv);

}  // namespace bodypoint::cli
