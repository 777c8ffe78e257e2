"""The store on a relational database (SQLite, PostgreSQL): ``vm.Store("plant.db")`` opens one."""

from .migrate import migrate
from .schema import is_sql_target
from .store import SQLStore

__all__ = ["SQLStore", "is_sql_target", "migrate"]
