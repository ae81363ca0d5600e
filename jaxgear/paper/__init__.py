"""The paper (S. Li, Tribol. Int. 88, 2015) reproduced: its reported values, the runs behind its
figures and table, Figs. 3-12, and the R1-R11 comparison (``jaxgear figures``)."""

from .figures import FIGURE_FILES as FIGURE_FILES
from .figures import figure as figure
from .figures import save_figures as save_figures
from .reference import FIGURES as FIGURES
from .reference import NOMINAL_POINTS_RPM as NOMINAL_POINTS_RPM
from .reference import PAPER_QUASI_STATIC_W as PAPER_QUASI_STATIC_W
from .reference import PAPER_RESULTS as PAPER_RESULTS
from .reference import PAPER_TRIBO_DYNAMIC_W as PAPER_TRIBO_DYNAMIC_W
from .reproduce import ContactField as ContactField
from .reproduce import FigureUnavailable as FigureUnavailable
from .reproduce import PaperReproduction as PaperReproduction
from .reproduce import field_contact as field_contact
from .reproduce import field_surfaces as field_surfaces
from .reproduce import reproduce_paper as reproduce_paper
from .table import paper_table as paper_table
from .table import table_markdown as table_markdown
from .table import write_report as write_report
