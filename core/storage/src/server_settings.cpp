#include "liversim/storage/server_settings.h"

#include <cctype>
#include <charconv>
#include <stdexcept>

namespace liversim {

namespace {

// The URL as a message may show it: a password in it is replaced by "***".
std::string shown(std::string_view url) {
  std::string text(url);
  const auto scheme = text.find("://");
  const auto start = scheme == std::string::npos ? 0 : scheme + 3;
  const auto end = text.find_first_of("/?", start);
  const auto at = text.rfind('@', end == std::string::npos ? std::string::npos : end);
  if (at != std::string::npos && at >= start) {
    const auto colon = text.find(':', start);
    if (colon < at) text.replace(colon + 1, at - colon - 1, "***");
  }
  for (auto p = text.find("password="); p != std::string::npos; p = text.find("password=", p + 1)) {
    const auto value = p + 9;
    text.replace(value, text.find('&', value) - value, "***");
  }
  return text;
}

std::invalid_argument bad_url(std::string_view url, const std::string& what) {
  return std::invalid_argument("server URL \"" + shown(url) + "\": " + what);
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string percent_decoded(std::string_view url, std::string_view part) {
  std::string out;
  for (std::size_t i = 0; i < part.size(); ++i) {
    if (part[i] != '%') {
      out += part[i];
      continue;
    }
    const int high = i + 2 < part.size() ? hex_digit(part[i + 1]) : -1;
    const int low = high >= 0 ? hex_digit(part[i + 2]) : -1;
    if (low < 0) throw bad_url(url, "a '%' is not followed by two hex digits");
    out += static_cast<char>(high * 16 + low);
    i += 2;
  }
  return out;
}

std::string percent_encoded(std::string_view text) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string out;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isalnum(u) || c == '-' || c == '.' || c == '_' || c == '~' || c == '/') {
      out += c;
    } else {
      out += '%';
      out += kHex[u >> 4];
      out += kHex[u & 15];
    }
  }
  return out;
}

int whole_number(std::string_view url, std::string_view text, const char* what, int low, int high) {
  int value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value < low || value > high)
    throw bad_url(url, std::string(what) + " \"" + std::string(text) + "\" is not a whole number " +
                           std::to_string(low) + " to " + std::to_string(high));
  return value;
}

}  // namespace

ServerSettings parse_server_url(std::string_view url) {
  std::string_view rest = url;
  bool scheme = false;
  for (const std::string_view prefix : {"postgresql://", "postgres://"}) {
    if (rest.starts_with(prefix)) {
      rest.remove_prefix(prefix.size());
      scheme = true;
      break;
    }
  }
  if (!scheme) throw bad_url(url, "it does not start with postgresql://");
  ServerSettings settings;
  std::string_view query;
  if (const auto q = rest.find('?'); q != std::string_view::npos) {
    query = rest.substr(q + 1);
    rest = rest.substr(0, q);
  }
  std::string_view authority = rest;
  if (const auto slash = rest.find('/'); slash != std::string_view::npos) {
    authority = rest.substr(0, slash);
    if (slash + 1 < rest.size()) settings.database = percent_decoded(url, rest.substr(slash + 1));
  }
  if (const auto at = authority.rfind('@'); at != std::string_view::npos) {
    const std::string_view user = authority.substr(0, at);
    if (user.find(':') != std::string_view::npos)
      throw bad_url(url,
                    "it holds a password; settings keep none (give it when connecting, or put it "
                    "in ~/.pgpass)");
    settings.user = percent_decoded(url, user);
    authority = authority.substr(at + 1);
  }
  std::string_view host = authority;
  if (host.starts_with('[')) {  // [IPv6]:port
    const auto close = host.find(']');
    if (close == std::string_view::npos) throw bad_url(url, "an IPv6 address has no ']'");
    settings.host = std::string(host.substr(1, close - 1));
    host = host.substr(close + 1);
    if (host.starts_with(':'))
      settings.port = whole_number(url, host.substr(1), "the port", 1, 65535);
    else if (!host.empty())
      throw bad_url(url, "unexpected \"" + std::string(host) + "\" after the address");
  } else {
    if (const auto colon = host.rfind(':'); colon != std::string_view::npos) {
      settings.port = whole_number(url, host.substr(colon + 1), "the port", 1, 65535);
      host = host.substr(0, colon);
    }
    settings.host = percent_decoded(url, host);
  }
  while (!query.empty()) {
    const auto amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view() : query.substr(amp + 1);
    const auto eq = pair.find('=');
    if (eq == std::string_view::npos)
      throw bad_url(url, "the option \"" + std::string(pair) + "\" has no value");
    const std::string key(pair.substr(0, eq));
    const std::string value = percent_decoded(url, pair.substr(eq + 1));
    if (key == "sslmode") {
      static constexpr std::string_view kModes[] = {"disable", "allow",     "prefer",
                                                    "require", "verify-ca", "verify-full"};
      bool known = false;
      for (const std::string_view mode : kModes) known = known || mode == value;
      if (!known)
        throw bad_url(url, "sslmode \"" + value +
                               "\" is none of disable, allow, prefer, require, verify-ca, "
                               "verify-full");
      settings.ssl_mode = value;
    } else if (key == "sslrootcert") {
      settings.ssl_root_cert = value;
    } else if (key == "sslcert") {
      settings.ssl_cert = value;
    } else if (key == "sslkey") {
      settings.ssl_key = value;
    } else if (key == "connect_timeout") {
      settings.connect_timeout_s = whole_number(url, value, "connect_timeout", 1, 3600);
    } else if (key == "password") {
      throw bad_url(url, "it holds a password; settings keep none");
    } else if (key == "host") {  // libpq's form for a socket folder: ?host=/run/postgresql
      settings.host = value;
    } else if (key == "port") {
      settings.port = whole_number(url, value, "the port", 1, 65535);
    } else if (key == "user") {
      settings.user = value;
    } else {
      throw bad_url(url, "unknown option \"" + key +
                             "\" (known: sslmode, sslrootcert, sslcert, sslkey, connect_timeout)");
    }
  }
  if (settings.host.empty()) throw bad_url(url, "it names no server");
  if (settings.database.empty()) throw bad_url(url, "it names no database");
  return settings;
}

std::string server_url(const ServerSettings& s) {
  std::string url = "postgresql://";
  if (!s.user.empty()) url += percent_encoded(s.user) + "@";
  const bool socket_folder = s.host.starts_with('/');
  // Appended piece by piece: GCC 12 misreads `"[" + s.host` as overlapping copies (-Wrestrict).
  if (!socket_folder) {
    if (s.host.find(':') != std::string::npos)
      url.append("[").append(s.host).append("]");
    else
      url += percent_encoded(s.host);
    url.append(":").append(std::to_string(s.port));
  }
  url.append("/").append(percent_encoded(s.database));
  std::string options = "sslmode=" + s.ssl_mode;
  if (socket_folder)
    options += "&host=" + percent_encoded(s.host) + "&port=" + std::to_string(s.port);
  if (!s.ssl_root_cert.empty())
    options += "&sslrootcert=" + percent_encoded(s.ssl_root_cert.string());
  if (!s.ssl_cert.empty()) options += "&sslcert=" + percent_encoded(s.ssl_cert.string());
  if (!s.ssl_key.empty()) options += "&sslkey=" + percent_encoded(s.ssl_key.string());
  if (s.connect_timeout_s != ServerSettings{}.connect_timeout_s)
    options += "&connect_timeout=" + std::to_string(s.connect_timeout_s);
  return url + "?" + options;
}

std::string server_name(const ServerSettings& s) {
  return (s.user.empty() ? "" : s.user + "@") + s.host + ":" + std::to_string(s.port) + "/" +
         s.database;
}

}  // namespace liversim
