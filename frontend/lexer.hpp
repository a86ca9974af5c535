// Tokens of the Frac language (grammar/frac.ebnf).
#pragma once

#include "frontend/diagnostics.hpp"

#include <string>
#include <string_view>
#include <vector>

namespace frac::front {

enum class Tok {
    end,
    ident,
    number,
    string,
    // keywords
    kw_fn,
    kw_const,
    kw_let,
    kw_in,
    kw_if,
    kw_then,
    kw_else,
    kw_and,
    kw_or,
    kw_not,
    kw_shape,
    kw_over,
    kw_test,
    kw_expect,
    kw_within,
    kw_import,
    kw_print,
    // punctuation
    lparen,
    rparen,
    lbracket,
    rbracket,
    lbrace,
    rbrace,
    comma,
    semicolon,
    colon,
    dot,
    dotdot,
    assign,
    eq,
    ne,
    lt,
    le,
    gt,
    ge,
    plus,
    minus,
    star,
    slash,
    caret,
    amp,
    bar,
    tilde,
    question, // ? (an unknown entry of a BCIFS operator)
    times,
    error
};

const char* token_name(Tok t);

struct Token {
    Tok kind = Tok::end;
    std::string_view text; // a view of the lexed text (a string's without its quotes)
    Location loc;
};

// Splits a file into tokens; malformed characters and unterminated strings or comments are reported
// to `diags` and skipped. The tokens view `text`, which must outlive them (hence no temporary string).
std::vector<Token> lex(std::string_view text, std::uint32_t file, Diagnostics& diags);
std::vector<Token> lex(std::string&& text, std::uint32_t file, Diagnostics& diags) = delete;

} // namespace frac::front
