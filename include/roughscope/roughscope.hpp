// Umbrella header: the whole public API of the roughscope library.
#pragma once

#include "roughscope/beckmann.hpp"
#include "roughscope/brdf_table.hpp"
#include "roughscope/comparison.hpp"
#include "roughscope/curet.hpp"
#include "roughscope/errors.hpp"
#include "roughscope/estimation.hpp"
#include "roughscope/fit.hpp"
#include "roughscope/geometry.hpp"
#include "roughscope/models.hpp"
#include "roughscope/retro.hpp"
#include "roughscope/scattering.hpp"
#include "roughscope/validity.hpp"
