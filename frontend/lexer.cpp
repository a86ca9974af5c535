#include "frontend/lexer.hpp"

#include <cctype>
#include <fmt/format.h>

namespace frac::front {

const char* token_name(Tok t) {
    switch (t) {
    case Tok::end: return "end of file";
    case Tok::ident: return "name";
    case Tok::number: return "number";
    case Tok::string: return "string";
    case Tok::kw_fn: return "'fn'";
    case Tok::kw_const: return "'const'";
    case Tok::kw_let: return "'let'";
    case Tok::kw_in: return "'in'";
    case Tok::kw_if: return "'if'";
    case Tok::kw_then: return "'then'";
    case Tok::kw_else: return "'else'";
    case Tok::kw_and: return "'and'";
    case Tok::kw_or: return "'or'";
    case Tok::kw_not: return "'not'";
    case Tok::kw_shape: return "'shape'";
    case Tok::kw_over: return "'over'";
    case Tok::kw_test: return "'test'";
    case Tok::kw_expect: return "'expect'";
    case Tok::kw_within: return "'within'";
    case Tok::kw_import: return "'import'";
    case Tok::kw_print: return "'print'";
    case Tok::lparen: return "'('";
    case Tok::rparen: return "')'";
    case Tok::lbracket: return "'['";
    case Tok::rbracket: return "']'";
    case Tok::lbrace: return "'{'";
    case Tok::rbrace: return "'}'";
    case Tok::comma: return "','";
    case Tok::semicolon: return "';'";
    case Tok::colon: return "':'";
    case Tok::dot: return "'.'";
    case Tok::dotdot: return "'..'";
    case Tok::assign: return "'='";
    case Tok::eq: return "'=='";
    case Tok::ne: return "'!='";
    case Tok::lt: return "'<'";
    case Tok::le: return "'<='";
    case Tok::gt: return "'>'";
    case Tok::ge: return "'>='";
    case Tok::plus: return "'+'";
    case Tok::minus: return "'-'";
    case Tok::star: return "'*'";
    case Tok::slash: return "'/'";
    case Tok::caret: return "'^'";
    case Tok::amp: return "'&'";
    case Tok::bar: return "'|'";
    case Tok::tilde: return "'~'";
    case Tok::question: return "'?'";
    case Tok::times: return "'×'";
    case Tok::error: return "invalid token";
    }
    return "token";
}

namespace {

// A word's keyword, or Tok::ident. A scan of the short list: a large model's words are mostly one to
// four letters, and most differ from every keyword in their first letter or length.
Tok keyword_or_ident(std::string_view word) {
    struct Keyword {
        std::string_view text;
        Tok kind;
    };
    static constexpr Keyword keywords[] = {
        {"fn", Tok::kw_fn},         {"const", Tok::kw_const},   {"let", Tok::kw_let},
        {"in", Tok::kw_in},         {"if", Tok::kw_if},         {"then", Tok::kw_then},
        {"else", Tok::kw_else},     {"and", Tok::kw_and},       {"or", Tok::kw_or},
        {"not", Tok::kw_not},       {"shape", Tok::kw_shape},   {"over", Tok::kw_over},
        {"test", Tok::kw_test},     {"expect", Tok::kw_expect}, {"within", Tok::kw_within},
        {"import", Tok::kw_import}, {"print", Tok::kw_print}};
    if (word.size() < 2 || word.size() > 6) return Tok::ident;
    for (const Keyword& k : keywords)
        if (k.text[0] == word[0] && k.text == word) return k.kind;
    return Tok::ident;
}

class Lexer {
public:
    Lexer(std::string_view text, std::uint32_t file, Diagnostics& diags)
        : s_(text), file_(file), diags_(diags) {
        if (s_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3; // a UTF-8 byte order mark, as editors write it
    }

    std::vector<Token> run() {
        std::vector<Token> out;
        // A token takes a character or two at the least: the list never moves while it grows, and the
        // pages reserved beyond its end are never touched.
        out.reserve(s_.size() / 2 + 1);
        for (;;) {
            skip_space_and_comments();
            Token t;
            t.loc = here();
            if (pos_ >= s_.size()) {
                t.kind = Tok::end;
                out.push_back(t);
                return out;
            }
            if (scan(t)) out.push_back(std::move(t));
        }
    }

private:
    Location here() const { return {file_, line_, col_}; }
    // The bytes of the well-formed UTF-8 character of two to four bytes at `at`, else 1.
    std::size_t utf8_length(std::size_t at) const {
        const auto lead = static_cast<unsigned char>(s_[at]);
        const std::size_t n = lead >= 0xC2 && lead <= 0xDF   ? 2
                              : lead >= 0xE0 && lead <= 0xEF ? 3
                              : lead >= 0xF0 && lead <= 0xF4 ? 4
                                                             : 1;
        if (n == 1 || at + n > s_.size()) return 1;
        for (std::size_t k = 1; k < n; ++k)
            if ((static_cast<unsigned char>(s_[at + k]) & 0xC0) != 0x80) return 1;
        return n;
    }
    char peek(std::size_t k = 0) const { return pos_ + k < s_.size() ? s_[pos_ + k] : '\0'; }
    void advance() {
        const char c = s_[pos_++];
        if (c == '\n') {
            ++line_;
            col_ = 1;
        } else if ((static_cast<unsigned char>(c) & 0xC0) != 0x80) {
            ++col_; // columns count characters, not UTF-8 continuation bytes
        }
    }

    void skip_space_and_comments() {
        for (;;) {
            while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(peek()))) advance();
            if (peek() == '/' && peek(1) == '/') {
                while (pos_ < s_.size() && peek() != '\n') advance();
            } else if (peek() == '/' && peek(1) == '*') {
                const Location start = here();
                advance();
                advance();
                while (pos_ < s_.size() && !(peek() == '*' && peek(1) == '/')) advance();
                if (pos_ >= s_.size()) {
                    diags_.error(start, "unterminated comment");
                    return;
                }
                advance();
                advance();
            } else {
                return;
            }
        }
    }

    bool scan(Token& t) {
        const char c = peek();
        const std::size_t start = pos_;
        if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
            while (std::isalnum(static_cast<unsigned char>(peek())) || peek() == '_') advance();
            t.text = s_.substr(start, pos_ - start);
            t.kind = keyword_or_ident(t.text);
            return true;
        }
        if (std::isdigit(static_cast<unsigned char>(c)) ||
            (c == '.' && std::isdigit(static_cast<unsigned char>(peek(1))))) {
            while (std::isdigit(static_cast<unsigned char>(peek()))) advance();
            // "0..5" is a range, not the number "0."
            if (peek() == '.' && peek(1) != '.') {
                advance();
                while (std::isdigit(static_cast<unsigned char>(peek()))) advance();
            }
            if ((peek() == 'e' || peek() == 'E') &&
                (std::isdigit(static_cast<unsigned char>(peek(1))) ||
                 ((peek(1) == '+' || peek(1) == '-') && std::isdigit(static_cast<unsigned char>(peek(2)))))) {
                advance();
                if (peek() == '+' || peek() == '-') advance();
                while (std::isdigit(static_cast<unsigned char>(peek()))) advance();
            }
            t.kind = Tok::number;
            t.text = s_.substr(start, pos_ - start);
            return true;
        }
        if (c == '"') {
            advance();
            while (pos_ < s_.size() && peek() != '"' && peek() != '\n') advance();
            if (peek() != '"') {
                diags_.error(t.loc, "unterminated string");
                return false;
            }
            t.kind = Tok::string;
            t.text = s_.substr(start + 1, pos_ - start - 1);
            advance();
            return true;
        }
        if (static_cast<unsigned char>(c) == 0xC3 &&
            static_cast<unsigned char>(peek(1)) == 0x97) { // U+00D7 ×
            advance();
            advance();
            t.kind = Tok::times;
            t.text = "×";
            return true;
        }
        struct Punct {
            const char* text;
            Tok kind;
        };
        static const Punct puncts[] = {
            {"..", Tok::dotdot},   {"==", Tok::eq},    {"!=", Tok::ne},     {"<=", Tok::le},
            {">=", Tok::ge},       {"(", Tok::lparen}, {")", Tok::rparen},  {"[", Tok::lbracket},
            {"]", Tok::rbracket},  {"{", Tok::lbrace}, {"}", Tok::rbrace},  {",", Tok::comma},
            {";", Tok::semicolon}, {":", Tok::colon},  {".", Tok::dot},     {"=", Tok::assign},
            {"<", Tok::lt},        {">", Tok::gt},     {"+", Tok::plus},    {"-", Tok::minus},
            {"*", Tok::star},      {"/", Tok::slash},  {"^", Tok::caret},   {"&", Tok::amp},
            {"|", Tok::bar},       {"~", Tok::tilde},  {"?", Tok::question}};
        for (const Punct& p : puncts) {
            if (p.text[0] != c) continue; // most tokens are punctuation: no string compare for the others
            const std::string_view text(p.text);
            if (s_.compare(pos_, text.size(), text) == 0) {
                for (std::size_t k = 0; k < text.size(); ++k) advance();
                t.kind = p.kind;
                t.text = text;
                return true;
            }
        }
        const std::size_t length = utf8_length(pos_);
        if (length > 1) {
            // One character of several bytes: one error, the character shown as written.
            diags_.error(t.loc, fmt::format("unexpected character '{}' (names and operators are ASCII)",
                                            s_.substr(pos_, length)));
            for (std::size_t k = 0; k < length; ++k) advance();
            return false;
        }
        std::string shown(1, c);
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7F)
            shown = fmt::format("\\x{:02x}", static_cast<unsigned char>(c));
        diags_.error(t.loc, fmt::format("unexpected character '{}'", shown));
        advance();
        return false;
    }

    std::string_view s_;
    std::uint32_t file_;
    Diagnostics& diags_;
    std::size_t pos_ = 0;
    std::uint32_t line_ = 1, col_ = 1;
};

} // namespace

std::vector<Token> lex(std::string_view text, std::uint32_t file, Diagnostics& diags) {
    return Lexer(text, file, diags).run();
}

} // namespace frac::front
