// The commands of the command line: `wavepath render`, `wavepath merge`, `wavepath devices`
// (`wavepath info` has a header of its own, info.h).
#pragma once

#include <chrono>
#include <exception>
#include <string>
#include <utility>

#include <CLI/CLI.hpp>

#include "host/cli/options.h"

namespace wp::cli {

// Lists the OpenCL platforms and devices (`wavepath devices`); throws when there is none.
int list_devices();

// `wavepath render`: the exit status (128 + the signal that stopped the passes, if one did).
// `program_start` is when wavepath started (--time-limit counts from it).
int render_command(const CLI::App& render, CliOptions& cli, wp::RenderSettings& settings,
                   std::chrono::steady_clock::time_point program_start);

// `wavepath merge`: films of one render's sample ranges, in any order, into one. Every part is
// read and checked (Film::read_info: without keeping its data) before anything is added or
// written: the same render key and size as the first part's, and ranges that neither overlap nor
// leave a gap (once sorted). Then the films are read again and added one at a time, in sample
// order, so that at most two are in memory.
int merge_command(CliOptions& cli);

// The message main() prints for an exception: one line, then the details (wp::Error's) if any.
std::pair<std::string, std::string> describe(const std::exception_ptr& error);

}  // namespace wp::cli
