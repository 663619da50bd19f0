"""placeholder"""
def add_parser(subparsers):
    return subparsers.add_parser("sweep")
def run(args):
    return 0
