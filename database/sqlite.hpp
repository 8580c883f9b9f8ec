#pragma once
// The store's Database, Statement and Transaction (SQLite file or PostgreSQL
// server): database/store.hpp.
#include "database/store.hpp"
