#pragma once
// The secret that every request to the viewer must carry: whoever else can reach 127.0.0.1 (other
// users of the machine, a web page in the user's own browser) cannot guess it.
#include <string>

namespace scalespace::viewer {

/// 128 bits from the kernel's CSPRNG (getrandom), as 32 lowercase hex digits. Throws Error when
/// the kernel gives no random bytes (never a predictable fallback).
std::string makeViewerToken();

/// Compares in time independent of where the strings differ (no timing oracle on the token).
bool tokensEqual(const std::string& a, const std::string& b);

}  // namespace scalespace::viewer
