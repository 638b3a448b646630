#pragma once
/// \file
/// `hapticctl query`: offline pair queries, one JSON object per line in, one result per line out
/// (format in docs/query.md and docs/architecture.md, "Pair queries").

#include <istream>
#include <ostream>

namespace hapticd::client {

/// Answers every line of `in` on `out`, in order. A bad line gets {"id": ..., "error": "..."} and
/// processing goes on. Returns the exit status: 0 when every line was answered, 1 otherwise.
int runQuery(std::istream& in, std::ostream& out);

}  // namespace hapticd::client
