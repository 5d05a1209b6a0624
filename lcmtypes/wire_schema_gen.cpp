// Build-time generator: reads the .lcm message definitions and writes a C++ header with their wire layout
// (members, types, array dimensions) as constant tables, plus the LCM fingerprint of each struct.
// lib/msg/wire_check.cpp walks those tables to bound every count of an incoming message before the
// lcm-gen decoder allocates from it. Because the tables come from the same .lcm files as the decoders,
// they cannot go stale; a test compares each table's fingerprint with the generated type's getHash().
//
// Usage: adit_wire_schema_gen OUTPUT.hpp FILE.lcm...
// Handles the LCM grammar the project uses: package, struct, const, primitive and struct members,
// several names per declaration, fixed and member-sized array dimensions.
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

struct Dim {
  bool variable = false;
  std::string size;  // the literal or the member name, as written (it enters the fingerprint)
};

struct Member {
  std::string name;
  std::string type;  // primitive name, or the struct's qualified name "package.name"
  std::vector<Dim> dims;
};

struct Struct {
  std::string package, name;
  std::vector<Member> members;
  std::string qualified() const { return package.empty() ? name : package + "." + name; }
};

const std::set<std::string> kPrimitives = {"int8_t", "int16_t", "int32_t", "int64_t", "byte",
                                           "float",  "double",  "string",  "boolean"};

std::string stripComments(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text.compare(i, 2, "//") == 0) {
      while (i < text.size() && text[i] != '\n') ++i;
      out += '\n';
    } else if (text.compare(i, 2, "/*") == 0) {
      const std::size_t end = text.find("*/", i + 2);
      if (end == std::string::npos) throw std::runtime_error("unterminated comment");
      i = end + 1;
      out += ' ';
    } else {
      out += text[i];
    }
  }
  return out;
}

std::vector<std::string> tokenize(const std::string& text) {
  std::vector<std::string> tokens;
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (std::isspace(c)) {
      ++i;
    } else if (std::isalnum(c) || c == '_' || c == '.' || c == '-' || c == '+') {
      std::size_t j = i;
      while (j < text.size() && (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '_' ||
                                 text[j] == '.' || text[j] == '-' || text[j] == '+'))
        ++j;
      tokens.push_back(text.substr(i, j - i));
      i = j;
    } else {
      tokens.emplace_back(1, text[i]);
      ++i;
    }
  }
  return tokens;
}

class Parser {
 public:
  Parser(std::vector<std::string> tokens, std::string file) : t_(std::move(tokens)), file_(std::move(file)) {}

  std::vector<Struct> parse() {
    std::vector<Struct> out;
    while (pos_ < t_.size()) {
      const std::string word = next();
      if (word == "package") {
        package_ = next();
        expect(";");
      } else if (word == "struct") {
        out.push_back(parseStruct());
      } else {
        fail("expected 'package' or 'struct', found '" + word + "'");
      }
    }
    return out;
  }

 private:
  Struct parseStruct() {
    Struct s;
    s.package = package_;
    s.name = next();
    expect("{");
    while (peek() != "}") {
      if (peek() == "const") {
        while (next() != ";") {
        }
        continue;
      }
      std::string type = next();
      if (!kPrimitives.count(type) && type.find('.') == std::string::npos && !package_.empty())
        type = package_ + "." + type;
      for (;;) {
        Member m;
        m.type = type;
        m.name = next();
        while (peek() == "[") {
          next();
          Dim d;
          d.size = next();
          d.variable = !std::isdigit(static_cast<unsigned char>(d.size[0]));
          if (d.variable && !isIntegerMember(s, d.size))
            fail("dimension '" + d.size + "' of '" + m.name + "' is not an earlier integer member");
          expect("]");
          m.dims.push_back(d);
        }
        s.members.push_back(m);
        const std::string sep = next();
        if (sep == ";") break;
        if (sep != ",") fail("expected ',' or ';' after member '" + m.name + "'");
      }
    }
    expect("}");
    return s;
  }

  static bool isIntegerMember(const Struct& s, const std::string& name) {
    for (const Member& m : s.members)
      if (m.name == name && m.dims.empty() &&
          (m.type == "int8_t" || m.type == "int16_t" || m.type == "int32_t" || m.type == "int64_t" || m.type == "byte"))
        return true;
    return false;
  }

  const std::string& peek() const {
    if (pos_ >= t_.size()) fail("unexpected end of file");
    return t_[pos_];
  }
  std::string next() {
    peek();
    return t_[pos_++];
  }
  void expect(const std::string& what) {
    const std::string got = next();
    if (got != what) fail("expected '" + what + "', found '" + got + "'");
  }
  [[noreturn]] void fail(const std::string& why) const { throw std::runtime_error(file_ + ": " + why); }

  std::vector<std::string> t_;
  std::string file_;
  std::string package_;
  std::size_t pos_ = 0;
};

// LCM's struct fingerprint (before nested types are mixed in), as lcm-gen computes it: member names, primitive
// type names and dimensions, never the struct's own name.
std::int64_t hashUpdate(std::int64_t v, char c) {
  const std::uint64_t shifted = static_cast<std::uint64_t>(v) << 8;
  return static_cast<std::int64_t>((shifted ^ static_cast<std::uint64_t>(v >> 55)) + static_cast<std::uint64_t>(
                                                                                          static_cast<std::int64_t>(c)));
}
std::int64_t hashString(std::int64_t v, const std::string& s) {
  v = hashUpdate(v, static_cast<char>(s.size()));
  for (char c : s) v = hashUpdate(v, c);
  return v;
}
std::uint64_t baseHash(const Struct& s) {
  std::int64_t v = 0x12345678;
  for (const Member& m : s.members) {
    v = hashString(v, m.name);
    if (kPrimitives.count(m.type)) v = hashString(v, m.type);
    v = hashUpdate(v, static_cast<char>(m.dims.size()));
    for (const Dim& d : m.dims) {
      v = hashUpdate(v, static_cast<char>(d.variable ? 1 : 0));
      v = hashString(v, d.size);
    }
  }
  return static_cast<std::uint64_t>(v);
}

std::string kindOf(const std::string& type) {
  static const std::map<std::string, std::string> kinds = {
      {"int8_t", "Int8"},   {"byte", "Int8"},     {"boolean", "Int8"},  {"int16_t", "Int16"}, {"int32_t", "Int32"},
      {"int64_t", "Int64"}, {"float", "Float"},   {"double", "Double"}, {"string", "String"}};
  const auto it = kinds.find(type);
  return it == kinds.end() ? "Struct" : it->second;
}

std::string cppName(const Struct& s) {
  std::string out = "::";
  for (char c : s.qualified()) out += c == '.' ? std::string("::") : std::string(1, c);
  return out;
}

std::string generate(const std::vector<Struct>& structs, const std::vector<std::string>& headers) {
  std::map<std::string, int> index;
  for (std::size_t i = 0; i < structs.size(); ++i) index[structs[i].qualified()] = static_cast<int>(i);
  std::ostringstream dims, members, table, traits, all;
  int num_dims = 0, num_members = 0;
  for (std::size_t i = 0; i < structs.size(); ++i) {
    const Struct& s = structs[i];
    const int first_member = num_members;
    for (const Member& m : s.members) {
      int nested = -1;
      if (kindOf(m.type) == "Struct") {
        const auto it = index.find(m.type);
        if (it == index.end()) throw std::runtime_error(s.qualified() + ": unknown type " + m.type);
        nested = it->second;
      }
      const int first_dim = num_dims;
      for (const Dim& d : m.dims) {
        int source = -1;
        for (std::size_t k = 0; k < s.members.size(); ++k)
          if (d.variable && s.members[k].name == d.size) source = static_cast<int>(k);
        dims << "    {" << (d.variable ? "-1" : d.size) << ", " << source << "},\n";
        ++num_dims;
      }
      members << "    {\"" << m.name << "\", Kind::" << kindOf(m.type) << ", " << nested << ", " << first_dim << ", "
              << m.dims.size() << "},\n";
      ++num_members;
    }
    char hash[32];
    std::snprintf(hash, sizeof hash, "0x%016llxULL", static_cast<unsigned long long>(baseHash(s)));
    table << "    {\"" << s.qualified() << "\", " << hash << ", " << first_member << ", " << s.members.size()
          << "},\n";
    traits << "template <> struct TypeIndex<" << cppName(s) << "> { static constexpr int value = " << i << "; };\n";
    all << (i ? ", " : "") << cppName(s);
  }
  std::ostringstream out;
  out << "// Generated by adit_wire_schema_gen from the .lcm files: do not edit.\n#pragma once\n\n"
      << "#include \"msg/wire_schema.hpp\"\n\n#include <tuple>\n\n";
  for (const std::string& h : headers) out << "#include <" << h << ">\n";
  out << "\nnamespace adit::msg::wire {\n\n"
      << "inline constexpr DimSchema kDims[] = {\n" << dims.str() << "    {0, -1}};\n\n"
      << "inline constexpr MemberSchema kMembers[] = {\n" << members.str() << "};\n\n"
      << "inline constexpr StructSchema kStructs[] = {\n" << table.str() << "};\n\n"
      << "inline constexpr int kNumStructs = " << structs.size() << ";\n\n"
      << traits.str() << "\n// Every message type defined in the .lcm files.\nusing AllTypes = std::tuple<" << all.str()
      << ">;\n\n}  // namespace adit::msg::wire\n";
  return out.str();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: adit_wire_schema_gen OUTPUT.hpp FILE.lcm...\n";
    return 2;
  }
  try {
    std::vector<Struct> structs;
    std::vector<std::string> headers;
    for (int i = 2; i < argc; ++i) {
      std::ifstream in(argv[i]);
      if (!in) throw std::runtime_error(std::string(argv[i]) + ": cannot read");
      std::stringstream text;
      text << in.rdbuf();
      for (Struct& s : Parser(tokenize(stripComments(text.str())), argv[i]).parse()) {
        std::string header = s.qualified();
        for (char& c : header)
          if (c == '.') c = '/';
        headers.push_back(header + ".hpp");
        structs.push_back(std::move(s));
      }
    }
    const std::string text = generate(structs, headers);
    const std::string tmp = std::string(argv[1]) + ".tmp";
    {
      std::ofstream out(tmp);
      out << text;
      if (!out) throw std::runtime_error(tmp + ": cannot write");
    }
    if (std::rename(tmp.c_str(), argv[1]) != 0) throw std::runtime_error(std::string(argv[1]) + ": cannot rename");
  } catch (const std::exception& e) {
    std::cerr << "adit_wire_schema_gen: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
