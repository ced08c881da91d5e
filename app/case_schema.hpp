// SPDX-License-Identifier: GPL-3.0-or-later
// The schema of a case file: the tables of keys that its readers declare, in reading order.
#pragma once
#include "common/schema.hpp"

namespace arlequin::app {

const Schema& case_schema();

}  // namespace arlequin::app
